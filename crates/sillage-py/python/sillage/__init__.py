"""sillage: track many moving objects in image sequences, from Python.

Fast particle tracking velocimetry (TracTrac's algorithm) implemented in Rust, returning
pandas DataFrames with trackpy's column names (``frame``, ``particle``, ``x``, ``y``), so that
``trackpy.emsd``, ``trackpy.filter_stubs`` or ``trackpy.plot_traj`` take them as they are.

Frames are numpy arrays: one 2-D frame, a 3-D stack ``(frames, rows, columns)`` or a list of
2-D frames, of ``uint8`` (divided by 255), ``uint16`` (divided by 65535) or ``float32`` /
``float64`` (taken as grey levels, 1 being full scale). They are read in place; the GIL is
released while sillage computes.

Parameters are the keys of sillage's configuration (``sillage config`` on the command line
lists them all with their defaults): a keyword names a key of the function's own section
(``detector`` for :func:`locate` and :func:`batch`, ``tracker`` for :func:`link`; for
:func:`ptv` the one section holding that key), ``section__key`` names any key, and the
``params`` dict takes dotted keys. Nested values are dicts::

    sillage.batch(frames, scale_px=2.5, threshold={"fixed": 0.02})
    sillage.ptv(frames, scale_px=2.5, motion_av=5, params={"preprocess.median": 3})

An unknown key or a bad value raises ``ValueError`` naming the key.

Example (the README's)::

    >>> import sillage, trackpy
    >>> frames, truth = sillage.synth_vortex(n_particles=500, n_frames=8, seed=1)
    >>> tracks = sillage.ptv(frames, scale_px=2.0)
    >>> msd = trackpy.emsd(trackpy.filter_stubs(tracks, 3), mpp=1.0, fps=1.0)
"""

from __future__ import annotations

import json
import numbers
import os
import sys
import warnings
from typing import Any, Iterable, Iterator, Mapping

import numpy as np
import pandas as pd

from . import _sillage

__version__ = _sillage.__version__

__all__ = ["locate", "batch", "ptv", "ptv_iter", "link", "track", "detect", "track_bedload",
           "evaluate", "fit", "bench", "synth_vortex", "synth_bedload", "config_keys"]

#: Column order of detections (trackpy's ``locate`` puts ``y`` before ``x``).
_DETECTION_COLUMNS = ["y", "x", "signal", "frame"]
#: Column order of trajectories.
_TRACK_COLUMNS = ["y", "x", "frame", "particle", "vx", "vy", "ax", "ay"]
#: Box columns of pedestrians and motion blobs, MOTChallenge's names (px).
_BOX_COLUMNS = ["bb_left", "bb_top", "bb_width", "bb_height"]
#: The columns :func:`track` returns for each tracker.
_TRACKER_COLUMNS = {
    "ptv": _TRACK_COLUMNS,
    "bedload": _TRACK_COLUMNS + ["state", "class"],
    "immpf": ["y", "x", "frame", "particle", "vx", "vy"] + _BOX_COLUMNS,
    "siftpf": ["y", "x", "frame", "particle"] + _BOX_COLUMNS,
}
#: The columns :func:`detect` returns for each detector.
_DETECTOR_COLUMNS = {
    "blob": _DETECTION_COLUMNS,
    "bead": _DETECTION_COLUMNS + ["class"],
    "motion": _DETECTION_COLUMNS + _BOX_COLUMNS,
}


def __getattr__(name: str) -> Any:
    """``sillage.dask`` is imported on first use (it needs the optional dask packages)."""
    if name == "dask":
        import importlib
        return importlib.import_module(".dask", __name__)
    raise AttributeError(f"module 'sillage' has no attribute {name!r}")


def config_keys() -> list[str]:
    """Every configuration key, dotted (``detector.scale_px``), optional ones included.

    >>> "tracker.motion_av" in sillage.config_keys()
    True
    """
    return list(_sillage.config_keys())


def locate(frame: np.ndarray, *, params: Mapping[str, Any] | None = None,
           **detector: Any) -> pd.DataFrame:
    """Detects the objects of one 2-D frame.

    Returns a DataFrame with one row per object: ``y``, ``x`` (sub-pixel centre, px; origin
    at the centre of the top-left pixel), ``signal`` (the band-pass filtered intensity at
    the centre) and ``frame`` (0). Keywords are ``detector`` keys (``scale_px``,
    ``threshold``, ``polarity``...), ``params`` any dotted keys.

    >>> spots = sillage.locate(frame, scale_px=2.0)
    >>> spots[["x", "y"]].head()
    """
    array = np.asarray(frame)
    if array.ndim != 2:
        raise ValueError(
            f"locate takes one 2-D frame (rows, columns); got a {array.ndim}-D array of shape "
            f"{array.shape}; use sillage.batch for a stack of frames")
    return batch(array, params=params, **detector)


def _columns_frame(columns: dict, order: list[str]) -> pd.DataFrame:
    """The DataFrame of the arrays ``columns`` (as the extension returns them) in ``order``,
    taking the arrays as they are: building it by copy then selecting the columns copied
    every value twice (1.6 s for 4 million PTV rows; this takes a millisecond)."""
    return pd.DataFrame({name: columns[name] for name in order}, copy=False)


def _frame_with_measured(columns: dict, order: list[str]) -> pd.DataFrame:
    """The DataFrame of ``columns`` in ``order``; what the run measured from the frames
    (``particle_sigma_px``, ``scale_px``, ``polarity``, ``source_density``, and for PTV
    ``displacement_px`` and ``vote_search_px``) goes to its ``attrs``; particle images too dense
    for PTV (see ``source_density``) and PTV on fewer than three frames raise a
    ``UserWarning``."""
    measured = columns.pop("measured", {})
    for key in ("density_warning", "frames_warning"):
        warning = measured.pop(key, None)
        if warning:
            warnings.warn(warning, stacklevel=3)
    frame = _columns_frame(columns, order)
    frame.attrs.update(measured)
    return frame


def batch(frames: np.ndarray | Iterable[np.ndarray], *,
          params: Mapping[str, Any] | None = None, progress: bool = False,
          **detector: Any) -> pd.DataFrame:
    """Detects the objects of every frame, like ``trackpy.batch``.

    ``frames`` is a 3-D array ``(frames, rows, columns)``, a 2-D frame or an iterable of 2-D
    frames of one shape. Returns the columns of :func:`locate`, ``frame`` being the frame's
    position in ``frames``. ``progress=True`` shows a progress bar (tqdm when installed).

    >>> features = sillage.batch(frames, scale_px=2.0)
    >>> features.groupby("frame").size()

    By default the particle size and polarity are measured on the first frame; the values
    used are in ``features.attrs`` (``particle_sigma_px``, ``scale_px``, ``polarity``).
    """
    source = _frames_argument(frames)
    with _progress(progress, _frame_count(source), "locate") as update:
        columns = _sillage.locate(source, _overrides(detector, params, "detector"), update)
    return _frame_with_measured(columns, _DETECTION_COLUMNS)


def ptv(frames: np.ndarray | Iterable[np.ndarray] | str, *,
        params: Mapping[str, Any] | None = None, progress: bool = False,
        **keywords: Any) -> pd.DataFrame:
    """Detects and tracks objects through a sequence (TracTrac's PTV).

    ``frames`` is what :func:`batch` takes, or a path: a folder of images, a glob pattern
    (``"run/*.tif"``), a multi-page TIFF or a video. Returns one row per track point:
    ``y``, ``x`` (px), ``frame``, ``particle`` (the trajectory id), ``vx``, ``vy``
    (px/frame) and ``ax``, ``ay`` (px/frame²). As in TracTrac, a point is reported when it
    is the middle of three linked frames, so the first and last frame carry none.

    Keywords name a key of the ``detector`` or ``tracker`` section (``scale_px``,
    ``motion_av``...), or ``section__key`` where the name is in both (``tracker__filter``);
    ``params`` takes dotted keys.

    >>> tracks = sillage.ptv("experiment/*.tif", scale_px=2.5, motion_av=5)
    >>> trackpy.filter_stubs(tracks, 5)
    """
    source = frames if isinstance(frames, str) else _frames_argument(frames)
    if hasattr(source, "__fspath__"):
        source = str(source)
    total = None if isinstance(source, str) else _frame_count(source)
    with _progress(progress, total, "ptv") as update:
        columns = _sillage.ptv(source, _overrides(keywords, params, None), update)
    return _frame_with_measured(columns, _TRACK_COLUMNS)


def ptv_iter(frames: Iterable[np.ndarray] | str, *,
             params: Mapping[str, Any] | None = None,
             **keywords: Any) -> Iterator[pd.DataFrame]:
    """Tracks a sequence frame by frame, yielding as it goes: for long sequences.

    ``frames`` is a path (as for :func:`ptv`) or any iterable of 2-D arrays (a pims
    sequence, a generator): only a few frames are ever held in memory. After each frame it
    yields the track points that became final, in the columns of :func:`ptv` (frame t-1's
    points once frame t + ``velocity_window`` // 2 - 1 is seen, frame t+2 with the default
    window of 7 frames; the rest after the last frame), so the DataFrames of all steps,
    concatenated, equal what :func:`ptv` returns. Keywords as for :func:`ptv`;
    ``training_passes`` must stay 0.

    >>> for points in sillage.ptv_iter("long_run/*.tif", scale_px=2.5):
    ...     update_statistics(points)
    """
    overrides = _overrides(keywords, params, None)
    if hasattr(frames, "__fspath__"):
        frames = str(frames)
    if isinstance(frames, str):
        stream = _sillage.PtvStream(overrides, frames)
        steps: Iterable[Any] = iter(stream.step, None)
    else:
        stream = _sillage.PtvStream(overrides)
        steps = (stream.step(np.asarray(frame)) for frame in frames)
    for columns in steps:
        yield _columns_frame(columns, _TRACK_COLUMNS)
    last = _columns_frame(stream.finish(), _TRACK_COLUMNS)
    if len(last):
        yield last


def link(features: pd.DataFrame, *, params: Mapping[str, Any] | None = None,
         progress: bool = False, **tracker: Any) -> pd.DataFrame:
    """Links detections into trajectories with the PTV tracker, like ``trackpy.link``.

    ``features`` has one row per detection with columns ``frame`` (integers), ``x`` and
    ``y`` (px), e.g. the output of :func:`batch` or ``trackpy.batch``. Returns a copy with
    a ``particle`` column (every row gets one; rows in no trajectory get ids of their own,
    as in trackpy) and the velocities ``vx``, ``vy`` (px/frame, NaN where unlinked).
    Keywords are ``tracker`` keys (``motion_av``, ``max_displacement_px``...). There is no
    ``search_range``: PTV links nearest neighbours around a predicted position.

    >>> tracks = sillage.link(trackpy.batch(frames, 7), max_displacement_px=5)
    """
    missing = [c for c in ("frame", "x", "y") if c not in features.columns]
    if missing:
        raise ValueError(
            f"the detections lack the column(s) {missing}; give a DataFrame with columns "
            f"frame, x, y (trackpy's layout)")
    frame = features["frame"].to_numpy()
    if not np.issubdtype(frame.dtype, np.integer):
        if not np.all(np.isfinite(frame)) or not np.all(np.mod(frame, 1) == 0):
            raise ValueError("the frame column must hold whole numbers")
    frame = np.ascontiguousarray(frame, dtype=np.int64)
    x = np.ascontiguousarray(features["x"].to_numpy(), dtype=np.float64)
    y = np.ascontiguousarray(features["y"].to_numpy(), dtype=np.float64)
    total = int(np.unique(frame).size) if progress else None
    with _progress(progress, total, "link") as update:
        columns = _sillage.link(frame, x, y, _overrides(tracker, params, "tracker"), update)
    # `assign` adds the three columns in one go: 10× cheaper than a copy then three
    # insertions on 200,000 rows (0.04 against 0.46 ms per frame of 20,000).
    return features.assign(**columns)


def track(source: str | Any, tracker: str = "ptv", *, seed: int = 1,
          sequence_params: str | Any | None = None, mask: str | Any | None = None,
          ground_plane: str | Any | None = None, motion_prior: str | Any | None = None,
          detections: str | Any | None = None, max_frames: int | None = None,
          window: int | None = None, overlap: int = _sillage.DEFAULT_OVERLAP,
          jobs: int | None = None,
          params: Mapping[str, Any] | None = None, progress: bool = False,
          **keywords: Any) -> pd.DataFrame:
    """Tracks the frames of ``source`` with any of sillage's four trackers.

    ``source`` is a path: a folder of images, a glob pattern (``"run/*.tif"``), a multi-page
    TIFF or a video (colour frames for the pedestrian trackers). ``tracker`` is

    * ``"ptv"``: TracTrac's particle tracking (as :func:`ptv`);
    * ``"bedload"``: the MMPF+ bead tracker on the bead detector's output, with motion
      states; give the bead sizes with ``sequence_params`` (BeadTracking's
      ``sequence_param.txt``) and the flume base with ``mask``;
    * ``"immpf"``: pedestrians, one IMM particle filter each (motion blobs as births, or
      the MOTChallenge ``detections`` file driving the filters; ``params=
      {"tracker.detection.with_frames": "births"}`` for births only); ``ground_plane`` (from
      ``sillage fit homography``) sizes the boxes, ``motion_prior`` feeds the MP model;
    * ``"siftpf"``: surveillance objects followed by their SIFT features' particle filters.

    Keywords are keys of that tracker's configuration (``sillage config`` for PTV and the
    bedload pipeline, ``sillage track immpf|siftpf --help``): a bare name is a key of the
    ``tracker`` section (for PTV, of the one section holding it), ``section__key`` any key,
    ``params`` dotted keys. ``seed`` seeds the particle filters.

    Returns one row per track point: ``y``, ``x`` (px; for pedestrians the box's foot point),
    ``frame``, ``particle``, then per tracker the velocities ``vx``, ``vy`` (px/frame),
    accelerations ``ax``, ``ay``, ``state`` and ``class`` (bedload) or the box
    ``bb_left``, ``bb_top``, ``bb_width``, ``bb_height`` (pedestrians).

    With ``window``, the sequence is tracked in windows of that many frames sharing
    ``overlap`` frames, ``jobs`` at once on this machine's cores (default: one per core), and
    stitched into one set of trajectories, as ``sillage ptv --window`` does (the same result
    as :func:`sillage.dask.track` on a cluster; see ``docs/scale.md``).

    >>> people = sillage.track("PETS09-S2L1/img1", "immpf", ground_plane="ground.toml",
    ...                        models=["cv", "ca"], seed=1)
    >>> people.groupby("particle").size()
    """
    if tracker not in _TRACKER_COLUMNS:
        raise ValueError(f"unknown tracker `{tracker}`; choose one of {sorted(_TRACKER_COLUMNS)}")
    section = None if tracker == "ptv" else "tracker"
    overrides = _overrides(keywords, params, section)
    if window is not None:
        if max_frames is not None:
            raise ValueError("give window or max_frames, not both")
        files = {name: _path(path) for name, path in [
            ("sequence_params", sequence_params), ("mask", mask),
            ("ground_plane", ground_plane), ("motion_prior", motion_prior),
            ("detections", detections)] if path is not None}
        jobs = (os.cpu_count() or 1) if jobs is None else int(jobs)
        with _progress(progress, None, f"{tracker} windows") as update:
            columns, summary = _sillage.track_windows(_path(source), tracker, overrides,
                                                      int(seed), files, int(window),
                                                      int(overlap), jobs, update)
        tracks = _columns_frame(columns, _TRACKER_COLUMNS[tracker])
        tracks.attrs["seams"] = json.loads(summary)["seams"]
        return tracks
    with _progress(progress, max_frames, tracker) as update:
        columns = _sillage.track(_path(source), tracker, overrides, int(seed),
                                 _optional_path(sequence_params), _optional_path(mask),
                                 _optional_path(ground_plane), _optional_path(motion_prior),
                                 _optional_path(detections), max_frames, update)
    return _columns_frame(columns, _TRACKER_COLUMNS[tracker])


def detect(source: str | Any, detector: str = "blob", *,
           sequence_params: str | Any | None = None, mask: str | Any | None = None,
           max_frames: int | None = None, params: Mapping[str, Any] | None = None,
           progress: bool = False, **keywords: Any) -> pd.DataFrame:
    """Detects objects in the frames of ``source`` (a path, as for :func:`track`).

    ``detector`` is ``"blob"`` (PTV's DoG/LoG blobs, as :func:`batch`), ``"bead"`` (the MMPF+
    black and transparent beads; ``sequence_params`` and ``mask`` as for :func:`track`) or
    ``"motion"`` (moving blobs over a Gaussian-mixture background, the pedestrian trackers'
    births). Keywords are keys of the detector's configuration (``detector`` section for
    blob and bead, the motion detector's own keys for motion), ``params`` dotted keys.

    Returns one row per detection: ``y``, ``x`` (px), ``signal`` (the detector's response;
    for motion blobs their area, px²), ``frame``, then ``class`` for beads (0 black,
    1 transparent) and the box columns ``bb_left``, ``bb_top``, ``bb_width``, ``bb_height``
    for motion blobs.

    >>> blobs = sillage.detect("PETS09-S2L1/img1", "motion", max_frames=50)
    """
    if detector not in _DETECTOR_COLUMNS:
        raise ValueError(
            f"unknown detector `{detector}`; choose one of {sorted(_DETECTOR_COLUMNS)}")
    section = "" if detector == "motion" else "detector"
    overrides = _overrides(keywords, params, section)
    with _progress(progress, max_frames, detector) as update:
        columns = _sillage.detect(_path(source), detector, overrides,
                                  _optional_path(sequence_params), _optional_path(mask),
                                  max_frames, update)
    return _columns_frame(columns, _DETECTOR_COLUMNS[detector])


def _path(source: Any) -> str:
    """A path argument as text (``str`` or any ``os.PathLike``)."""
    if hasattr(source, "__fspath__"):
        return str(source.__fspath__())
    if not isinstance(source, str):
        raise TypeError(f"source must be a path (a str or a pathlib.Path), not "
                        f"{type(source).__name__}")
    return source


def _optional_path(path: Any) -> str | None:
    return None if path is None else _path(path)


def track_bedload(detections: pd.DataFrame, *, candidates: pd.DataFrame | None = None,
                  params: Mapping[str, Any] | None = None, **keywords: Any) -> pd.DataFrame:
    """Tracks beads with MMPF+ or a baseline of its Table 1 (``tracker="mmpf"``, ``"pf"``,
    ``"imm"``, ``"det"``), with motion states.

    ``detections`` has one row per detected bead: ``frame``, ``x``, ``y`` (px), and
    optionally ``class`` (0 black, 1 transparent; default 0) and ``score`` (default 1).
    ``candidates`` (same columns) are the detector-confidence candidates of Eq. (1). Keywords
    are keys of the bedload configuration (``sillage track bedload --help``; e.g. ``seed``,
    ``radius_px=[15, 10]``, ``survival={"max_missed": 5}``). Returns the columns of
    :func:`ptv` plus ``state`` (resting, rolling, saltating, unknown) and ``class``.

    >>> beads = sillage.track_bedload(detections, tracker="mmpf_plus", seed=1)
    >>> beads.groupby("state").size()
    """
    def columns(table: pd.DataFrame, name: str) -> tuple[np.ndarray, ...]:
        missing = [c for c in ("frame", "x", "y") if c not in table.columns]
        if missing:
            raise ValueError(f"{name} lacks the column(s) {missing}; give frame, x, y")
        n = len(table)
        return (np.ascontiguousarray(table["frame"], dtype=np.int64),
                np.ascontiguousarray(table["x"], dtype=np.float64),
                np.ascontiguousarray(table["y"], dtype=np.float64),
                np.ascontiguousarray(table["class"] if "class" in table else np.zeros(n),
                                     dtype=np.int64),
                np.ascontiguousarray(table["score"] if "score" in table else np.ones(n),
                                     dtype=np.float64))

    overrides: list[str] = []
    for key, value in {**keywords, **(params or {})}.items():
        _assign(key.replace("__", "."), value, overrides)
    found = columns(detections, "detections")
    extra = None if candidates is None else columns(candidates, "candidates")
    result = _sillage.track_bedload(found, overrides, extra)
    return _columns_frame(result, _TRACK_COLUMNS + ["state", "class"])


def evaluate(truth: pd.DataFrame, tracks: pd.DataFrame, *, match: str | None = None,
             match_px: float | None = None, radius_px: float | Iterable[float] | None = None,
             papers: bool = False) -> dict:
    """CLEAR MOT, IDF1 and HOTA of ``tracks`` against ``truth``, as ``sillage eval mot``
    scores files (TrackEval's conventions).

    Both tables have one row per object and frame with ``frame`` and ``particle`` (trackpy's
    layout), and what the rule ``match`` compares:

    * ``"dist:R"`` (the default, R = ``match_px`` or 1): points ``x``, ``y`` (px) at most R
      apart — particles, e.g. :func:`synth_vortex`'s truth and :func:`ptv`'s tracks;
    * ``"iou[:T]"``: boxes ``bb_left``, ``bb_top``, ``bb_width``, ``bb_height`` with IoU at
      least T (0.5) — pedestrians, e.g. :func:`track` with ``"immpf"``;
    * ``"disc[:T]"``: discs at ``x``, ``y`` with IoU at least T (0.43, the MMPF+ paper's) —
      beads; their radius is a ``radius`` column or ``radius_px``, one number or one per
      ``class`` (``[15, 10]`` for the shared flume's black and transparent beads).

    Returns ``{"clear": {"mota", "motp", "id_switches", ...}, "identity": {"idf1", ...},
    "hota": {"hota", "det_a", "ass_a", ...}}`` (HOTA averaged over the localisation
    thresholds, and per threshold), with ``"papers"`` (the papers' own scores: MMPF+ correct
    tracks, VACE, ETISEO) when ``papers=True``: the ``combined`` scores of
    ``sillage eval mot --json``.

    >>> scores = sillage.evaluate(truth, sillage.ptv(frames), match="dist:1")
    >>> scores["clear"]["mota"], scores["identity"]["idf1"]
    """
    if match is None:
        if match_px is not None and not float(match_px) > 0:
            raise ValueError(f"match_px = {match_px}: give a distance > 0 px")
        match = f"dist:{1.0 if match_px is None else float(match_px)}"
    elif match_px is not None:
        raise ValueError("give match (e.g. match='dist:2') or match_px, not both")
    rule = match.split(":", 1)[0].strip().lower()

    def columns(table: pd.DataFrame, name: str) -> tuple[Any, ...]:
        needed = {"iou": ["bb_left", "bb_top", "bb_width", "bb_height"]}.get(rule, ["x", "y"])
        missing = [c for c in ["frame", "particle", *needed] if c not in table.columns]
        if missing:
            raise ValueError(f"{name} lacks the column(s) {missing} that match={match!r} "
                             f"compares")
        n = len(table)

        def column(key: str) -> np.ndarray:
            values = table[key] if key in table.columns else np.full(n, np.nan)
            return np.ascontiguousarray(values, dtype=np.float64)

        if rule == "disc" and "radius" not in table.columns:
            if radius_px is None:
                raise ValueError(f"{name}: match={match!r} compares discs; give a radius "
                                 f"column or radius_px (one number, or one per class)")
            radii = np.atleast_1d(np.asarray(radius_px, dtype=np.float64))
            classes = (np.asarray(table["class"], dtype=np.int64) if "class" in table.columns
                       else np.zeros(n, dtype=np.int64))
            if radii.size == 1:
                radius = np.full(n, radii[0])
            elif classes.size and (classes.min() < 0 or classes.max() >= radii.size):
                raise ValueError(f"{name}: a class outside 0..{radii.size - 1} has no radius "
                                 f"in radius_px")
            else:
                radius = radii[classes]
        else:
            radius = column("radius")
        return (np.ascontiguousarray(table["frame"], dtype=np.int64),
                np.ascontiguousarray(table["particle"], dtype=np.int64),
                [column(k) for k in ("x", "y", "bb_left", "bb_top", "bb_width", "bb_height")]
                + [np.ascontiguousarray(radius, dtype=np.float64)])

    combined = json.loads(_sillage.evaluate(columns(truth, "truth"), columns(tracks, "tracks"),
                                            match, bool(papers)))
    scores = combined["metrics"]
    if "papers" in combined:
        scores["papers"] = combined["papers"]
    return scores


def fit(kind: str, truth: str | Any, *, out: str | Any | None = None,
        tracks: str | Any | None = None) -> dict:
    """Learns model parameters from ground truth, as ``sillage fit KIND`` does.

    ``kind`` is ``"bedload"`` (the MMPF+ motion parameters and transition table from a
    BeadTracking truth with motion states), ``"homography"`` (the image ↔ ground homography
    and the adult's box size from a MOT15 ``gt.txt`` with world coordinates) or
    ``"motion-prior"`` (the IMM-PF's learned motion prior, 30-px cells, from a MOTChallenge
    ``gt.txt``). ``out`` writes the file the command line writes (a bedload TOML
    configuration, a ground-plane TOML, a prior JSON), which :func:`track` then takes
    (``params``, ``ground_plane=``, ``motion_prior=``). ``tracks`` (bedload only): the output
    of ``sillage track bedload`` on the truth's frames (BeadTracking CSV); the motion-state
    smoother's evidence is then learnt too (``emission``, ``[smoother.emission]``). Returns
    what was fitted as a dict.

    >>> sillage.fit("homography", "PETS09-S2L1/gt/gt.txt", out="ground.toml")["boxes"]
    """
    return json.loads(_sillage.fit(kind, _path(truth), _optional_path(out),
                                   _optional_path(tracks)))


def bench(kind: str, sequences: Iterable[str | Any], *, runs: int = 1,
          models: Iterable[str] = ("CV", "CA", "CV_CA"),
          selections: Iterable[str] = ("whole-object", "detection-order", "reliability"),
          ground_plane: str | Any | None = None, max_frames: int | None = None,
          params: Mapping[str, Any] | None = None, progress: bool = False,
          **keywords: Any) -> pd.DataFrame:
    """A paper's table on MOTChallenge sequence folders (``img1/``, ``gt/gt.txt``), as
    ``sillage bench immpf|siftpf`` computes it: one row per sequence and model combination
    (``kind="immpf"``, ``models`` as the paper writes them) or feature selection
    (``kind="siftpf"``, ``selections`` among whole-object, detection-order, reliability),
    each score the median over the seeds ``1..runs``. Keywords are ``tracker`` keys of that
    tracker. Returns a DataFrame (scores as columns; for SIFT-PF the rows of all sequences
    combined come last, ``sequence == "COMBINED"``).

    >>> sillage.bench("immpf", ["PETS09-S2L1"], runs=5, models=["CV_CA", "CV_CA_MP"])
    """
    folders = [_path(s) for s in sequences]
    overrides = _overrides(keywords, params, "tracker")
    total = None
    with _progress(progress, total, f"bench {kind}") as update:
        if kind == "immpf":
            rows = json.loads(_sillage.bench_immpf(folders, list(models), int(runs), overrides,
                                                   _optional_path(ground_plane), max_frames,
                                                   update))
        elif kind == "siftpf":
            report = json.loads(_sillage.bench_siftpf(folders, [str(s) for s in selections],
                                                      int(runs), overrides,
                                                      _optional_path(ground_plane), max_frames,
                                                      update))
            rows = report["sequences"] + report["combined"]
        else:
            raise ValueError(f"unknown bench `{kind}`; choose immpf or siftpf")
    return pd.json_normalize(rows, sep="_")


def synth_vortex(*, out: str | Any | None = None,
                 **params: Any) -> tuple[np.ndarray, pd.DataFrame]:
    """Renders the synthetic vortex flow of the TracTrac paper (§4.1.1), with ground truth.

    Keywords are the generator's keys: ``width``, ``height`` (px, default 1024),
    ``n_particles`` (1000), ``n_frames`` (100), ``delta`` (the time step, 0.01), ``snr`` (4),
    ``intermittency`` (0), ``brownian`` (0), ``blob_sigma_px`` (2), ``peak`` (0.5), ``seed``
    (0). Returns the frames, a float32 array ``(frames, rows, columns)`` of grey levels in
    [0, 1], and the truth: one row per particle and frame with ``frame``, ``particle``,
    ``x``, ``y`` and the true displacement to the next frame ``vx``, ``vy``. With ``out`` (a
    folder), the frames are also written there as 16-bit PNG ``frame_00000.png``... with
    ``truth.csv``, as ``sillage synth vortex`` writes them.

    >>> frames, truth = sillage.synth_vortex(n_particles=500, n_frames=8, seed=1)
    >>> frames.shape
    (8, 1024, 1024)
    """
    assignments: list[str] = []
    for name, value in params.items():
        _assign(name, value, assignments)
    frames, truth = _sillage.synth_vortex(assignments, None if out is None else _path(out))
    return frames, pd.DataFrame(truth)


def synth_bedload(*, detection: Mapping[str, Any] | None = None,
                  **scene: Any) -> tuple[pd.DataFrame, pd.DataFrame, pd.DataFrame]:
    """Generates a synthetic bedload sequence (glass beads in a channel, MMPF+ §4.2): the true
    beads, with motion states, and what a bead detector reports of them.

    Keywords are the scene's keys: ``n_frames`` (default 200), ``n_black`` (black beads,
    bed included, 300), ``n_transparent`` (100), ``width``, ``height`` (1280 × 320 px),
    ``seed`` (0), ``transition_probabilities``...; ``detection`` holds the detector model's:
    ``position_sigma_px`` (0.5), ``transparent_miss_probability`` (0.03),
    ``burst_probability`` (0.01), ``false_positive_mean`` (1.0)... (the fields of the Rust
    ``BedloadSceneParams`` and ``BedloadDetectionParams`` document them all; list values are
    lists). Returns three DataFrames:

    * ``truth``: one row per bead and frame with ``frame``, ``particle``, ``x``, ``y`` (px),
      ``vx``, ``vy`` (the displacement *from the previous* frame, NaN in a bead's first),
      ``state`` (``resting``, ``rolling``, ``saltating``) and ``class`` (0 black,
      1 transparent): the truth :func:`evaluate` takes;
    * ``detections``: ``frame``, ``x``, ``y``, ``class``, ``score``, with misses, noise and
      false positives;
    * ``candidates``: the same columns, the detector-confidence candidates of Eq. (1)
      (transparent beads only),

    as :func:`track_bedload` reads them.

    >>> truth, detections, candidates = sillage.synth_bedload(n_frames=50, seed=1,
    ...                                                       detection={"position_sigma_px": 1.0})
    >>> beads = sillage.track_bedload(detections, candidates=candidates, seed=1)
    >>> sillage.evaluate(truth, beads, match="dist:5")["clear"]["mota"]
    """
    scene_overrides: list[str] = []
    for name, value in scene.items():
        _assign(name, value, scene_overrides)
    detection_overrides: list[str] = []
    for name, value in (detection or {}).items():
        _assign(name, value, detection_overrides)
    truth, detections, candidates = _sillage.synth_bedload(scene_overrides, detection_overrides)
    return pd.DataFrame(truth), pd.DataFrame(detections), pd.DataFrame(candidates)


def _frames_argument(frames: Any) -> Any:
    """An array as is; any other iterable of frames as a list of arrays."""
    if isinstance(frames, np.ndarray):
        return frames
    if isinstance(frames, (str, bytes)) or not isinstance(frames, Iterable):
        raise TypeError(
            f"frames must be a numpy array or an iterable of 2-D arrays, not "
            f"{type(frames).__name__}")
    return [np.asarray(frame) for frame in frames]


def _frame_count(frames: Any) -> int:
    if isinstance(frames, np.ndarray):
        return 1 if frames.ndim == 2 else len(frames)
    return len(frames)


def _overrides(keywords: Mapping[str, Any], params: Mapping[str, Any] | None,
               section: str | None) -> list[str]:
    """``key=value`` overrides with dotted keys, values written as TOML: a bare keyword is a
    key of ``section`` (of the configuration's top level when ``section`` is empty; for
    ``None``, of the one section of :func:`config_keys` holding it)."""
    assignments: list[str] = []
    keys = None
    for name, value in keywords.items():
        if "__" in name:
            dotted = name.replace("__", ".")
        elif section == "":
            dotted = name
        elif section is not None:
            dotted = f"{section}.{name}"
        else:
            keys = keys if keys is not None else config_keys()
            dotted = _resolve(name, keys)
        _assign(dotted, value, assignments)
    for key, value in (params or {}).items():
        _assign(key, value, assignments)
    return assignments


def _resolve(name: str, keys: list[str]) -> str:
    """The dotted key a bare keyword of :func:`ptv` names."""
    def owns(key: str, prefix: str) -> bool:
        return key == prefix or key.startswith(prefix + ".")

    if any(owns(key, name) for key in keys):
        return name
    sections = sorted({key.split(".")[0] for key in keys
                       if "." in key and owns(key, key.split(".")[0] + "." + name)})
    if len(sections) == 1:
        return f"{sections[0]}.{name}"
    if not sections:
        raise ValueError(
            f"unknown parameter `{name}`; sillage.config_keys() lists every key "
            f"(write section__key or use params={{'section.key': value}})")
    raise ValueError(
        f"parameter `{name}` is in several sections ({', '.join(sections)}); write "
        + " or ".join(f"{s}__{name}" for s in sections))


def _assign(key: str, value: Any, assignments: list[str]) -> None:
    """Appends ``key=value`` (nested dicts become dotted keys)."""
    if isinstance(value, Mapping):
        for sub, sub_value in value.items():
            _assign(f"{key}.{sub}", sub_value, assignments)
        return
    assignments.append(f"{key}={_toml(key, value)}")


def _toml(key: str, value: Any) -> str:
    """``value`` as a TOML value."""
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        number = float(value)
        if np.isnan(number):
            return "nan"
        if np.isinf(number):
            return "inf" if number > 0 else "-inf"
        return repr(number)
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml(key, v) for v in value) + "]"
    raise ValueError(
        f"parameter `{key}`: cannot use a value of type {type(value).__name__}; give a "
        f"number, a bool, a string, a list or a dict")


class _progress:
    """A progress bar updated once per frame (tqdm when installed, else a line on stderr);
    yields its ``update`` callable, or None when ``enabled`` is false."""

    def __init__(self, enabled: bool, total: int | None, description: str) -> None:
        self.enabled, self.total, self.description = enabled, total, description
        self.bar: Any = None
        self.done = 0

    def __enter__(self):
        if not self.enabled:
            return None
        try:
            from tqdm.auto import tqdm
        except ImportError:
            return self._print
        self.bar = tqdm(total=self.total, desc=self.description, unit="frame")
        return self.bar.update

    def _print(self, n: int) -> None:
        self.done += n
        of = f"/{self.total}" if self.total else ""
        print(f"\r{self.description}: {self.done}{of} frames", end="", file=sys.stderr,
              flush=True)

    def __exit__(self, *exc: Any) -> None:
        if self.bar is not None:
            self.bar.close()
        elif self.enabled:
            print(file=sys.stderr)
