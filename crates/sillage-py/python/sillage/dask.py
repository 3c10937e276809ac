"""A long sequence tracked in time windows on a Dask cluster, stitched into one set of
trajectories.

The sequence is cut into windows of ``window`` frames, consecutive ones sharing ``overlap``
frames; each window is tracked on its own by a Dask worker (frames read by the worker from a
path every worker sees, or sent from an array), and the windows are stitched where they are:
each seam pairs the tracks of the overlap on a worker, and only the windows' track ids and
the seams come to the client, which renumbers identities globally (see ``docs/scale.md``). The result depends on ``window``, ``overlap`` and ``seed``, never on the
number of workers; it agrees with the single run of :func:`sillage.track` except for what a
window's first frames cannot know (their warm-up), measured in ``docs/scale.md``.

Needs ``dask`` and ``distributed``: ``pip install 'sillage[dask]'``. Progress shows on the
Dask dashboard (``client.dashboard_link``).

>>> import dask
>>> from distributed import Client, LocalCluster
>>> with dask.config.set(sillage.dask.FAST_WORKERS):
...     client = Client(LocalCluster(n_workers=8, threads_per_worker=1))
>>> tracks = sillage.dask.track("/shared/run42/*.tif", "ptv", window=500, client=client)
"""

from __future__ import annotations

import json
import operator
import os
from typing import Any, Mapping

import numpy as np
import pandas as pd

from . import _TRACKER_COLUMNS, _columns_frame, _overrides, _path, _sillage

__all__ = ["track", "agreement", "DEFAULT_OVERLAP", "FAST_WORKERS"]

#: Frames shared by consecutive windows when ``overlap`` is not given (the command line's
#: default; chosen on synthetic vortex flows, see ``docs/scale.md``).
DEFAULT_OVERLAP: int = _sillage.DEFAULT_OVERLAP

#: Dask settings for workers that track: Dask's nanny starts workers with
#: ``MALLOC_TRIM_THRESHOLD_=65536`` (to hand freed memory back to the system at once), which
#: turns off glibc's adaptive thresholds, so that every frame buffer is fresh memory the
#: kernel must map and zero. Measured on 2 cores (2048², 25,000 particles, 100 frames a
#: window): a window tracked in 6.1 s alone and 7.6-7.9 s beside another under Dask's
#: default, 6.0 s and 6.8-7.0 s without it. Give them when you start your workers, e.g.
#: ``with dask.config.set(sillage.dask.FAST_WORKERS): cluster = LocalCluster(...)``;
#: :func:`track` uses them for the cluster it starts itself. The cost: a worker keeps freed
#: memory for reuse instead of returning it at once. A local nanny also sets the variable in
#: the process that starts it, so start such clusters before any other in that process.
FAST_WORKERS: dict = {"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}


def track(source: str | os.PathLike | np.ndarray, tracker: str = "ptv", *, window: int,
          overlap: int = DEFAULT_OVERLAP, client: Any = None, out: str | os.PathLike | None = None,
          seed: int = 1, sequence_params: str | os.PathLike | None = None,
          mask: str | os.PathLike | None = None, ground_plane: str | os.PathLike | None = None,
          motion_prior: str | os.PathLike | None = None,
          detections: str | os.PathLike | None = None, retries: int = 2,
          params: Mapping[str, Any] | None = None, **keywords: Any) -> pd.DataFrame | list[str]:
    """Tracks ``source`` in windows of ``window`` frames on the workers of ``client``.

    ``source`` is a path every worker can read (a folder of images, a glob pattern, a
    multi-page TIFF or a video whose frame count is known) or a numpy array of frames
    ``(frames, rows, columns)`` (PTV and bedload; each window's frames are sent to its
    worker). ``tracker``, ``seed``, the files and the keywords are those of
    :func:`sillage.track`. ``overlap`` (at least 4, at most half the window) is the number of
    frames consecutive windows share.

    ``client`` is a ``distributed.Client``; without one, the current client is used, or a
    ``LocalCluster`` on this machine is started for the call (with :data:`FAST_WORKERS`).
    A window whose task raised is tried again up to ``retries`` times; a window whose worker
    died is rescheduled by Dask.

    The windows are stitched where they are: each seam is joined on a worker from the two
    windows' points in the overlap, and each window's share of the result (the frames
    between its two cuts) is made on the worker that holds the window; only the windows'
    track ids and the seams come to this process, to hand out the global identities.

    Returns the trajectories in the columns of :func:`sillage.track`, frame by frame; with
    ``out`` (a folder), the workers write them instead as partitioned Parquet,
    ``part-00000.parquet`` onwards, one per window, the frames from its first cut to its
    second (needs pyarrow on the workers), and the paths are returned.
    The stitcher's report per seam is in ``tracks.attrs["seams"]`` (or, with ``out``, in
    ``seams.json`` beside the parts).
    """
    try:
        import dask
        import distributed
    except ImportError as error:
        raise ImportError(
            "sillage.dask needs dask and distributed: pip install 'sillage[dask]'") from error
    if tracker not in _TRACKER_COLUMNS:
        raise ValueError(f"unknown tracker `{tracker}`; choose one of {sorted(_TRACKER_COLUMNS)}")
    overrides = _overrides(keywords, params, None if tracker == "ptv" else "tracker")
    files = {name: _path(path) for name, path in [
        ("sequence_params", sequence_params), ("mask", mask), ("ground_plane", ground_plane),
        ("motion_prior", motion_prior), ("detections", detections)] if path is not None}
    spec = (tracker, overrides, int(seed), files)
    if isinstance(source, np.ndarray):
        if source.ndim != 3:
            raise ValueError(f"an array source holds frames (frames, rows, columns); got "
                             f"{source.ndim} dimensions")
        frames = len(source)
    else:
        source = _path(source)
        frames = _sillage.frame_count(source)
    windows = _sillage.plan_windows(frames, int(window), int(overlap), *spec)
    if out is not None:
        _require_pyarrow()
    # Decided once here, on the sequence's first frames, so that every window detects and
    # links alike (particle size and polarity, PTV's displacement voting).
    measured = _sillage.measure_first_frames(source, *spec)

    own_client = None
    if client is None:
        try:
            client = distributed.get_client()
        except ValueError:
            with dask.config.set(FAST_WORKERS):
                cluster = distributed.LocalCluster(processes=True)
            own_client = client = distributed.Client(cluster)
    try:
        token = os.urandom(4).hex()
        tracks, edges = _submit(client, source, spec, measured, windows, retries, token)
        return _stitch(client, tracks, edges, spec, out, retries, token)
    finally:
        if own_client is not None:
            own_client.close()
            own_client.cluster.close()


def agreement(single: pd.DataFrame, stitched: pd.DataFrame,
              cuts: list | None = None) -> dict:
    """How far a windowed run ``stitched`` agrees with the single run ``single`` of the same
    frames: the share of the single run's points present in ``stitched`` at the same frame
    and position (``points``), and of its trajectories with points on both sides of a cut the
    share whose points carry one identity in ``stitched`` (``identities``, of ``crossing``).
    ``cuts`` default to the seams in ``stitched.attrs["seams"]``.

    >>> sillage.dask.agreement(sillage.track(path), sillage.dask.track(path, window=500))
    {'points': 0.9999, 'identities': 0.998, 'crossing': 2225}
    """
    if cuts is None:
        cuts = [seam["cut"] for seam in stitched.attrs.get("seams", [])]
    keys = ["frame", "x", "y"]
    merged = single.merge(stitched[keys + ["particle"]], on=keys, how="left",
                          suffixes=("", "_stitched"))
    found = merged["particle_stitched"].notna()
    spans = single.groupby("particle")["frame"].agg(["min", "max"])
    crossing = spans[[any(lo < cut <= hi for cut in cuts)
                      for lo, hi in zip(spans["min"], spans["max"])]].index
    ids = merged[merged["particle"].isin(crossing) & found]
    one_identity = ids.groupby("particle")["particle_stitched"].nunique() == 1
    return {"points": float(found.mean()) if len(found) else 1.0,
            "identities": float(one_identity.mean()) if len(one_identity) else 1.0,
            "crossing": int(len(crossing))}


def _submit(client: Any, source: Any, spec: tuple, measured: str, windows: list,
            retries: int, token: str) -> tuple[list, list]:
    """One task per window (an array's windows are scattered to the workers first); returns
    the futures of the windows' tracks and of their edges, both where the window was
    tracked."""
    tracks, edges = [], []
    for k, (index, first, last) in enumerate(windows):
        frames = source
        if isinstance(source, np.ndarray):
            [frames] = client.scatter([np.ascontiguousarray(source[first:last + 1])])
        neighbours = (windows[k - 1][2] if k > 0 else None,
                      windows[k + 1][1] if k + 1 < len(windows) else None)
        both = client.submit(_track_window, frames, spec, measured, index, first, last,
                             neighbours, key=f"sillage-window-{index}-{token}",
                             retries=retries, pure=False)
        tracks.append(client.submit(operator.itemgetter(0), both,
                                    key=f"sillage-tracks-{index}-{token}"))
        edges.append(client.submit(operator.itemgetter(1), both,
                                   key=f"sillage-edges-{index}-{token}"))
    return tracks, edges


def _track_window(frames: Any, spec: tuple, measured: str, index: int, first: int,
                  last: int, neighbours: tuple) -> tuple[bytes, bytes]:
    """Runs on a worker: the window's tracks and its edges (for the seams with the windows
    ending and starting at ``neighbours``), as bytes, its kernels on the worker's threads."""
    threads = _worker_threads()
    track = _sillage.track_window if isinstance(frames, str) else _sillage.track_window_frames
    return track(frames, *spec, index, first, last, measured, threads, *neighbours)


def _worker_threads() -> int | None:
    """The number of threads of the worker running this task (None outside a worker)."""
    try:
        from distributed import get_worker
        worker = get_worker()
    except (ImportError, ValueError):
        return None
    state = getattr(worker, "state", worker)
    return int(getattr(state, "nthreads", 0)) or None


def _stitch(client: Any, window_tracks: list, edges: list, spec: tuple, out: Any,
            retries: int, token: str) -> pd.DataFrame | list[str]:
    """Stitches the windows where they are: each seam (from the two windows' edges) and each
    window's share of the result are tasks on the workers (a share written there as a
    Parquet part with ``out``); only the windows' track ids and the seams come here, in
    window order, to hand out the global identities."""
    columns = _TRACKER_COLUMNS[spec[0]]
    count = len(window_tracks)

    def task(name: str, k: int, function: Any, *arguments: Any) -> Any:
        return client.submit(function, *arguments, key=f"sillage-{name}-{k}-{token}",
                             retries=retries)

    ids = [task("ids", k, _sillage.window_ids, edges[k]) for k in range(count)]
    seams = [task("seam", k, _sillage.join_seam, edges[k - 1], edges[k], *spec)
             for k in range(1, count)]
    edges.clear()  # each lives on as long as a seam needs it
    planner = _sillage.PartPlanner()
    shares = []

    def share(k: int, plan: bytes) -> None:
        path = None if out is None else os.path.join(os.fspath(out), f"part-{k:05d}.parquet")
        shares.append(task("share", k, _window_share, window_tracks[k], plan, columns, path))
        window_tracks[k] = None  # the window's tracks are freed once its share is made

    if out is not None:
        os.makedirs(out, exist_ok=True)
    for k in range(count):
        seam = seams[k - 1].result() if k > 0 else None
        plan = planner.push(ids[k].result(), seam)
        ids[k] = None
        if plan is not None:
            share(k - 1, plan)
    plan, report = planner.finish()
    if plan is not None:
        share(count - 1, plan)
    results = client.gather(shares)
    if out is not None:
        _write_text(os.path.join(os.fspath(out), "seams.json"), report)
        return results
    tracks = pd.concat(results, ignore_index=True) if results else pd.DataFrame(columns=columns)
    tracks.attrs["seams"] = json.loads(report)
    return tracks


def _window_share(tracks: bytes, plan: bytes, columns: list[str],
                  path: str | None) -> pd.DataFrame | str:
    """Runs on a worker: the window's share of the stitched run, as a DataFrame, or written
    to ``path`` as Parquet (whole or absent) and the path returned."""
    part = _columns_frame(_sillage.window_share(tracks, plan), columns)
    if path is None:
        return part
    _write_atomically(path, lambda partial: part.to_parquet(partial, index=False))
    return path


def _require_pyarrow() -> None:
    try:
        import pyarrow  # noqa: F401
    except ImportError as error:
        raise ImportError("writing Parquet needs pyarrow: pip install pyarrow") from error


def _write_atomically(path: str, write: Any) -> None:
    """Calls ``write(partial)`` on a temporary name beside ``path``, then renames it: the file
    is whole or absent."""
    partial = os.path.join(os.path.dirname(path), f".{os.path.basename(path)}.partial")
    write(partial)
    os.replace(partial, path)


def _write_text(path: str, text: str) -> None:
    def write(partial: str) -> None:
        with open(partial, "w", encoding="utf-8") as file:
            file.write(text)
    _write_atomically(path, write)
