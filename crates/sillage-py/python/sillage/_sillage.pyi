"""Type stubs of the native module (the public API is in ``sillage/__init__.py``)."""

from typing import Any, Callable, Optional

import numpy as np

__version__: str
DEFAULT_OVERLAP: int

Columns = dict[str, np.ndarray]
Progress = Optional[Callable[[int], Any]]

def config_keys() -> list[str]: ...
def locate(frames: Any, overrides: list[str], progress: Progress = None) -> Columns: ...
def ptv(source: Any, overrides: list[str], progress: Progress = None) -> Columns: ...
def link(
    frame: np.ndarray,
    x: np.ndarray,
    y: np.ndarray,
    overrides: list[str],
    progress: Progress = None,
) -> Columns: ...
def synth_vortex(overrides: list[str], out: Optional[str] = None) -> tuple[np.ndarray, Columns]: ...
def synth_bedload(
    scene_overrides: list[str], detection_overrides: list[str]
) -> tuple[Columns, Columns, Columns]: ...

class PtvStream:
    def __init__(self, overrides: list[str], path: Optional[str] = None) -> None: ...
    def step(self, frame: Optional[np.ndarray] = None) -> Optional[Columns]: ...
    def finish(self) -> Columns: ...

def evaluate(
    truth: tuple[np.ndarray, np.ndarray, list[np.ndarray]],
    tracks: tuple[np.ndarray, np.ndarray, list[np.ndarray]],
    rule: str,
    papers: bool = False,
) -> str: ...
def track_bedload(
    detections: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    overrides: list[str],
    candidates: Optional[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = None,
) -> Columns: ...
def track(
    source: str,
    tracker: str,
    overrides: list[str],
    seed: int = 1,
    sequence_params: Optional[str] = None,
    mask: Optional[str] = None,
    ground_plane: Optional[str] = None,
    motion_prior: Optional[str] = None,
    detections: Optional[str] = None,
    max_frames: Optional[int] = None,
    progress: Progress = None,
) -> Columns: ...
def detect(
    source: str,
    detector: str,
    overrides: list[str],
    sequence_params: Optional[str] = None,
    mask: Optional[str] = None,
    max_frames: Optional[int] = None,
    progress: Progress = None,
) -> Columns: ...
def fit(kind: str, truth: str, out: Optional[str] = None) -> str: ...
def bench_immpf(
    folders: list[str],
    combinations: list[str],
    runs: int,
    overrides: list[str],
    ground_plane: Optional[str] = None,
    max_frames: Optional[int] = None,
    progress: Progress = None,
) -> str: ...
def bench_siftpf(
    folders: list[str],
    selections: list[str],
    runs: int,
    overrides: list[str],
    ground_plane: Optional[str] = None,
    max_frames: Optional[int] = None,
    progress: Progress = None,
) -> str: ...

Files = dict[str, str]
Window = tuple[int, int, int]

def frame_count(source: str) -> int: ...
def plan_windows(
    frames: int, window: int, overlap: int, tracker: str, overrides: list[str], seed: int,
    files: Files,
) -> list[Window]: ...
def measure_first_frames(
    source: Any, tracker: str, overrides: list[str], seed: int, files: Files,
) -> str: ...
def track_window(
    source: str, tracker: str, overrides: list[str], seed: int, files: Files, index: int,
    first: int, last: int, measured: Optional[str] = None, threads: Optional[int] = None,
    previous_last: Optional[int] = None, next_first: Optional[int] = None,
) -> tuple[bytes, bytes]: ...
def track_window_frames(
    frames: np.ndarray, tracker: str, overrides: list[str], seed: int, files: Files,
    index: int, first: int, last: int, measured: Optional[str] = None,
    threads: Optional[int] = None, previous_last: Optional[int] = None,
    next_first: Optional[int] = None,
) -> tuple[bytes, bytes]: ...
def track_windows(
    source: str, tracker: str, overrides: list[str], seed: int, files: Files, window: int,
    overlap: int, jobs: int, progress: Progress = None,
) -> tuple[Columns, str]: ...

def window_ids(edges: bytes) -> bytes: ...
def join_seam(
    earlier: bytes, later: bytes, tracker: str, overrides: list[str], seed: int, files: Files,
) -> bytes: ...
def window_share(tracks: bytes, plan: bytes) -> Columns: ...

class PartPlanner:
    def __init__(self) -> None: ...
    def push(self, ids: bytes, seam: Optional[bytes] = None) -> Optional[bytes]: ...
    def finish(self) -> tuple[Optional[bytes], str]: ...
