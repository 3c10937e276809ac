//! numpy frames → sillage [`Frame`]s: one 2-D array, a 3-D stack or a list of 2-D arrays of
//! uint8, uint16, float32 or float64, read in place (no copy on the Python side) and converted
//! to grey levels in `[0, 1]` one frame at a time, with the GIL released.

use std::path::PathBuf;

use numpy::ndarray::{ArrayView2, ArrayViewD, Axis, Ix2};
use numpy::{PyReadonlyArrayDyn, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyList, PyTuple};
use sillage::core::{FrameIndex, GrayImage, Result};
use sillage::io::Frame;

/// The name frames made from arrays carry where files name theirs (error messages).
const ARRAY_PATH: &str = "<numpy array>";

/// One array as numpy holds it, borrowed read-only for the call.
enum Borrowed<'py> {
    U8(PyReadonlyArrayDyn<'py, u8>),
    U16(PyReadonlyArrayDyn<'py, u16>),
    F32(PyReadonlyArrayDyn<'py, f32>),
    F64(PyReadonlyArrayDyn<'py, f64>),
}

/// One frame's pixels, viewed in place.
#[derive(Clone, Copy)]
pub enum Pixels<'a> {
    /// 8-bit: divided by 255.
    U8(ArrayView2<'a, u8>),
    /// 16-bit: divided by 65535.
    U16(ArrayView2<'a, u16>),
    /// Floats: taken as grey levels already (1 is full scale).
    F32(ArrayView2<'a, f32>),
    /// Floats: taken as grey levels already (1 is full scale).
    F64(ArrayView2<'a, f64>),
}

impl Pixels<'_> {
    /// (rows, columns).
    pub fn shape(&self) -> (usize, usize) {
        match self {
            Pixels::U8(v) => v.dim(),
            Pixels::U16(v) => v.dim(),
            Pixels::F32(v) => v.dim(),
            Pixels::F64(v) => v.dim(),
        }
    }

    /// The grey image of these pixels, row-major whatever the array's strides.
    fn to_gray(self) -> Result<GrayImage> {
        fn convert<T: Copy>(view: ArrayView2<'_, T>, unit: impl Fn(T) -> f32) -> Result<GrayImage> {
            let (rows, columns) = view.dim();
            let data = match view.as_slice() {
                Some(slice) => slice.iter().map(|&v| unit(v)).collect(),
                None => view.iter().map(|&v| unit(v)).collect(),
            };
            GrayImage::from_vec(columns, rows, data)
        }
        match self {
            Pixels::U8(v) => convert(v, |p| f32::from(p) / 255.0),
            Pixels::U16(v) => convert(v, |p| f32::from(p) / 65535.0),
            Pixels::F32(v) => convert(v, |p| p),
            Pixels::F64(v) => convert(v, |p| p as f32),
        }
    }
}

/// The arrays of a call, borrowed while it runs.
pub struct FrameArrays<'py> {
    arrays: Vec<Borrowed<'py>>,
}

impl<'py> FrameArrays<'py> {
    /// Borrows `frames`: one numpy array (2-D: one frame; 3-D: frames along the first axis)
    /// or a list or tuple of 2-D arrays. Wrong types, dimensions and dtypes raise here.
    pub fn borrow(frames: &Bound<'py, PyAny>) -> PyResult<Self> {
        let arrays = if frames.cast::<PyUntypedArray>().is_ok() {
            vec![borrow_array(frames, None)?]
        } else if frames.cast::<PyList>().is_ok() || frames.cast::<PyTuple>().is_ok() {
            frames
                .try_iter()?
                .enumerate()
                .map(|(i, item)| borrow_array(&item?, Some(i)))
                .collect::<PyResult<_>>()?
        } else {
            return Err(PyTypeError::new_err(format!(
                "frames must be a numpy array or a list of numpy arrays, not {}",
                frames.get_type().name()?
            )));
        };
        Ok(Self { arrays })
    }

    /// Every frame, in order; an error when they differ in shape or one is empty.
    pub fn views(&self) -> PyResult<Vec<Pixels<'_>>> {
        let mut views = Vec::new();
        for array in &self.arrays {
            match array {
                Borrowed::U8(a) => split(a.as_array(), Pixels::U8, &mut views),
                Borrowed::U16(a) => split(a.as_array(), Pixels::U16, &mut views),
                Borrowed::F32(a) => split(a.as_array(), Pixels::F32, &mut views),
                Borrowed::F64(a) => split(a.as_array(), Pixels::F64, &mut views),
            }
        }
        if let Some(first) = views.first() {
            let first = first.shape();
            if first.0 == 0 || first.1 == 0 {
                return Err(PyValueError::new_err(format!(
                    "frame 0 is empty (shape {first:?}); give frames with pixels"
                )));
            }
            if let Some((i, other)) = views.iter().enumerate().find(|(_, v)| v.shape() != first) {
                return Err(PyValueError::new_err(format!(
                    "frames must all have the same shape: frame 0 is {first:?} but frame {i} is \
                     {:?}; crop or pad them to one size",
                    other.shape()
                )));
            }
        }
        Ok(views)
    }
}

/// The frames of `views` as sillage frames, converted one at a time as they are pulled.
pub fn frames_of<'a>(views: &'a [Pixels<'a>]) -> impl Iterator<Item = Result<Frame>> + 'a {
    views.iter().enumerate().map(|(i, pixels)| {
        Ok(Frame {
            index: i as FrameIndex,
            path: PathBuf::from(ARRAY_PATH),
            image: pixels.to_gray()?,
            colour: None,
        })
    })
}

/// Appends the 2-D frames of `array` (2-D: itself; 3-D: its slices along axis 0).
fn split<'a, T>(
    array: ArrayViewD<'a, T>,
    wrap: fn(ArrayView2<'a, T>) -> Pixels<'a>,
    views: &mut Vec<Pixels<'a>>,
) {
    match array.ndim() {
        2 => views.push(wrap(
            array.into_dimensionality::<Ix2>().expect("checked 2-D"),
        )),
        _ => views.extend((0..array.len_of(Axis(0))).map(|i| {
            let frame = array.clone().index_axis_move(Axis(0), i);
            wrap(frame.into_dimensionality::<Ix2>().expect("checked 3-D"))
        })),
    }
}

/// Borrows one array, checking its dimensions and dtype; `item` is its place in a list.
fn borrow_array<'py>(object: &Bound<'py, PyAny>, item: Option<usize>) -> PyResult<Borrowed<'py>> {
    let which = match item {
        Some(i) => format!("frames[{i}]"),
        None => "frames".to_string(),
    };
    let array = object.cast::<PyUntypedArray>().map_err(|_| {
        PyTypeError::new_err(format!(
            "{which} must be a numpy array, not {}",
            object
                .get_type()
                .name()
                .map_or_else(|_| "?".into(), |n| n.to_string())
        ))
    })?;
    let allowed = if item.is_some() { 2..=2 } else { 2..=3 };
    if !allowed.contains(&array.ndim()) {
        let wanted = if item.is_some() {
            "a 2-D frame (rows, columns)"
        } else {
            "a 2-D frame (rows, columns) or a 3-D stack (frames, rows, columns)"
        };
        return Err(PyValueError::new_err(format!(
            "{which} must be {wanted}; got a {}-D array of shape {:?} (convert colour to grey \
             first)",
            array.ndim(),
            array.shape()
        )));
    }
    if let Ok(a) = object.extract() {
        return Ok(Borrowed::U8(a));
    }
    if let Ok(a) = object.extract() {
        return Ok(Borrowed::U16(a));
    }
    if let Ok(a) = object.extract() {
        return Ok(Borrowed::F32(a));
    }
    if let Ok(a) = object.extract() {
        return Ok(Borrowed::F64(a));
    }
    Err(PyTypeError::new_err(format!(
        "{which} has dtype {}; use uint8, uint16, float32 or float64 (e.g. frame.astype(np.float32))",
        array.dtype()
    )))
}
