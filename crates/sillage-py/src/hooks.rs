//! What a run does in Python between two frames while the GIL is released: check for Ctrl-C
//! and advance the progress bar, each taking the GIL back for a moment.

use std::cell::RefCell;

use pyo3::prelude::*;
use sillage::core::{Error, Result};

use crate::errors::to_py;

/// The between-frames calls of one run, and the first Python error they met.
pub struct Between {
    progress: Option<Py<PyAny>>,
    error: RefCell<Option<PyErr>>,
}

impl Between {
    /// Calls `progress(1)` after every frame when given (a tqdm bar's `update`).
    pub fn new(progress: Option<Py<PyAny>>) -> Self {
        Self {
            progress,
            error: RefCell::new(None),
        }
    }

    /// `frames`, ending with an error as soon as Ctrl-C is pressed or a callback failed.
    pub fn frames<'a, T: 'a>(
        &'a self,
        frames: impl Iterator<Item = Result<T>> + 'a,
    ) -> impl Iterator<Item = Result<T>> + 'a {
        frames.map(move |frame| {
            self.check()?;
            frame
        })
    }

    /// An error as soon as Ctrl-C is pressed or a callback failed, to stop the run.
    pub fn check(&self) -> Result<()> {
        let signals = Python::attach(|py| py.check_signals());
        if let Err(e) = signals {
            self.keep(e);
        }
        if self.error.borrow().is_some() {
            return Err(Error::input("stopped from Python"));
        }
        Ok(())
    }

    /// Advances the progress bar by one frame.
    pub fn advance(&self) {
        if let Some(progress) = &self.progress {
            let called = Python::attach(|py| progress.call1(py, (1,)).map(drop));
            if let Err(e) = called {
                self.keep(e);
            }
        }
    }

    /// The run's result as Python sees it: the Python error met between frames first.
    pub fn result<T>(&self, result: Result<T>) -> PyResult<T> {
        match self.error.borrow_mut().take() {
            Some(e) => Err(e),
            None => result.map_err(to_py),
        }
    }

    fn keep(&self, error: PyErr) {
        self.error.borrow_mut().get_or_insert(error);
    }
}
