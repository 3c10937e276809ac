"""Tests of the sillage Python package: layouts trackpy accepts, errors, the README example."""

import pathlib
import re

import numpy as np
import pandas as pd
import pytest
import trackpy

import sillage

README = pathlib.Path(__file__).resolve().parents[3] / "README.md"


@pytest.fixture(scope="module")
def vortex():
    return sillage.synth_vortex(width=256, height=256, n_particles=200, n_frames=8, seed=3)


def readme_python_example() -> str:
    text = README.read_text(encoding="utf-8")
    section = text.split("## From Python", 1)[1]
    blocks = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    assert blocks, "README.md has no ```python block under '## From Python'"
    return blocks[0]


def test_readme_example_runs():
    namespace: dict = {}
    exec(compile(readme_python_example(), "README.md", "exec"), namespace)
    tracks, msd = namespace["tracks"], namespace["msd"]
    assert tracks.particle.nunique() > 100
    assert len(msd) >= 3 and (msd.to_numpy()[:3] > 0).all()


def test_synth_vortex_frames_and_truth(vortex):
    frames, truth = vortex
    assert frames.shape == (8, 256, 256) and frames.dtype == np.float32
    assert 0.0 <= frames.min() and frames.max() <= 1.0
    assert list(truth.columns) == ["frame", "particle", "x", "y", "vx", "vy"]
    assert (truth.groupby("frame").size() == 200).all()


def test_batch_finds_the_true_particles(vortex):
    frames, truth = vortex
    features = sillage.batch(frames, scale_px=2.0)
    assert list(features.columns) == ["y", "x", "signal", "frame"]
    assert sorted(features.frame.unique()) == list(range(8))
    first = features[features.frame == 0][["x", "y"]].to_numpy()
    true = truth[truth.frame == 0][["x", "y"]].to_numpy()
    nearest = np.sqrt(((true[:, None, :] - first[None, :, :]) ** 2).sum(-1)).min(axis=1)
    assert (nearest < 1.0).mean() > 0.75  # overlapping spots merge


def test_dtypes_and_layouts_give_the_same_detections(vortex):
    frames, _ = vortex
    as_u16 = np.round(frames * 65535).astype(np.uint16)
    reference = sillage.batch(as_u16)
    for variant in (as_u16.astype(np.float64) / 65535, list(as_u16),
                    np.asfortranarray(as_u16)):
        other = sillage.batch(variant)
        assert len(other) == len(reference)
        np.testing.assert_allclose(other[["x", "y"]], reference[["x", "y"]], atol=1e-3)
    # By default the particle size is measured on the first frame given, so a frame located
    # alone matches the batch when the size is given.
    given = {"scale_px": 2.0, "polarity": "bright"}
    single = sillage.locate(as_u16[2], **given)
    in_batch = sillage.batch(as_u16, **given)
    np.testing.assert_allclose(single[["x", "y"]],
                               in_batch[in_batch.frame == 2][["x", "y"]], atol=1e-9)
    u8 = sillage.batch((frames * 255).astype(np.uint8))
    assert abs(len(u8) - len(reference)) < 0.1 * len(reference)


def test_measured_particle_images_and_displacements_are_in_attrs(vortex):
    frames, _ = vortex
    features = sillage.batch(frames)
    assert features.attrs["polarity"] == "bright"
    # The vortex fixture draws particle images of σ = 2 px.
    assert 1.7 < features.attrs["particle_sigma_px"] < 2.5
    assert 0.5 < features.attrs["scale_px"] <= features.attrs["particle_sigma_px"]
    assert 0 < features.attrs["source_density"] < 0.5
    assert "density_warning" not in features.attrs
    tracks = sillage.ptv(frames)
    assert tracks.attrs["particle_sigma_px"] == features.attrs["particle_sigma_px"]
    assert tracks.attrs["displacement_px"] > 0
    # A given size is used as given: nothing measured.
    assert "particle_sigma_px" not in sillage.batch(frames, scale_px=2.0, polarity="bright").attrs


def test_particle_images_too_dense_for_ptv_raise_a_warning():
    rng = np.random.default_rng(3)
    rows, columns = np.mgrid[0:160, 0:160]
    frame = 0.02 * rng.random((160, 160))
    # 0.05 particles per pixel of σ 2.5 px: their images cover the frame.
    for x, y in rng.random((1280, 2)) * 160:
        frame += 0.5 * np.exp(-((columns - x) ** 2 + (rows - y) ** 2) / (2 * 2.5**2))
    with pytest.warns(UserWarning, match="source density"):
        features = sillage.batch(frame[None].astype(np.float32))
    assert features.attrs["source_density"] >= 0.5


def test_ptv_passes_through_trackpy(vortex):
    frames, truth = vortex
    tracks = sillage.ptv(frames, scale_px=2.0, motion_av=5)
    assert list(tracks.columns[:4]) == ["y", "x", "frame", "particle"]
    assert tracks.frame.min() == 1 and tracks.frame.max() == 6
    stubs = trackpy.filter_stubs(tracks, threshold=6)
    assert 0 < stubs.particle.nunique() < tracks.particle.nunique() + 1
    assert (stubs.groupby("particle").size() >= 6).all()
    msd = trackpy.emsd(stubs, mpp=1.0, fps=1.0)
    # The vortex moves particles by about a pixel a frame: the MSD grows with the lag.
    assert np.all(np.diff(msd.to_numpy()) > 0)
    speed = np.hypot(tracks.vx, tracks.vy)
    true_speed = np.hypot(truth.vx, truth.vy)
    assert abs(speed.median() - true_speed.median()) < 0.2 * true_speed.median()
    trackpy.plot_traj(stubs, plot_style={}).figure.clf() if _has_matplotlib() else None


def _has_matplotlib() -> bool:
    try:
        import matplotlib
        matplotlib.use("Agg")
        return True
    except ImportError:
        return False


def test_ptv_reads_a_folder_and_maps_missing_files(tmp_path, vortex):
    frames, _ = vortex
    with pytest.raises(FileNotFoundError, match="nothing_here"):
        sillage.ptv(str(tmp_path / "nothing_here"))
    stack = tmp_path / "stack.npy"
    np.save(stack, frames)
    with pytest.raises(ValueError):
        sillage.ptv(str(stack))


def test_link_matches_ptv_on_its_own_detections(vortex):
    frames, truth = vortex
    features = sillage.batch(frames, scale_px=2.0)
    linked = sillage.link(features, motion_av=5)
    assert len(linked) == len(features)
    assert list(linked.columns) == list(features.columns) + ["particle", "vx", "vy"]
    assert linked.particle.notna().all() and linked.particle.dtype == np.int64
    tracks = sillage.ptv(frames, scale_px=2.0, motion_av=5)
    inner = linked[linked.vx.notna()]
    assert len(inner) == len(tracks)
    # Rows that link to nothing have ids of their own, as in trackpy.
    singles = linked[linked.vx.isna()].particle
    assert singles.min() > inner.particle.max()
    # Linking the true positions recovers the true trajectories.
    true_links = sillage.link(truth[["frame", "x", "y"]], motion_av=5)
    inner = true_links[true_links.vx.notna()].copy()
    inner["truth"] = truth.particle[inner.index]
    purity = inner.groupby("particle").truth.nunique()
    assert (purity == 1).mean() > 0.95


def test_link_leaves_gaps_unlinked():
    rows = [(f, 10.0 + f, 20.0) for f in (0, 1, 2, 3, 5, 6, 7, 8)]
    df = pd.DataFrame(rows, columns=["frame", "x", "y"])
    linked = sillage.link(df)
    before = linked[linked.frame <= 3].particle
    after = linked[linked.frame >= 5].particle
    assert not set(before) & set(after)


def test_link_errors_name_the_problem():
    with pytest.raises(ValueError, match="frame"):
        sillage.link(pd.DataFrame({"x": [1.0], "y": [2.0]}))
    with pytest.raises(ValueError, match="whole numbers"):
        sillage.link(pd.DataFrame({"frame": [0.5], "x": [1.0], "y": [2.0]}))
    with pytest.raises(ValueError, match="tracker.motion_avg"):
        sillage.link(pd.DataFrame({"frame": [0], "x": [1.0], "y": [2.0]}), motion_avg=3)


def test_bad_frames_raise_errors_naming_the_problem(vortex):
    frames, _ = vortex
    with pytest.raises(ValueError, match="4-D array"):
        sillage.batch(np.zeros((2, 3, 4, 5), dtype=np.float32))
    with pytest.raises(ValueError, match="same shape.*frame 1"):
        sillage.batch([np.zeros((5, 5), np.uint8), np.zeros((6, 5), np.uint8)])
    with pytest.raises(ValueError, match="same shape"):
        sillage.ptv([frames[0], frames[1][:100]])
    with pytest.raises(TypeError, match="int32"):
        sillage.batch(np.zeros((4, 4), np.int32))
    with pytest.raises(ValueError, match="3-D"):
        sillage.locate(frames)


def test_unknown_and_bad_parameters_raise_value_errors_naming_the_key(vortex):
    frames, _ = vortex
    with pytest.raises(ValueError, match="detector.scale_pix"):
        sillage.batch(frames, scale_pix=2.0)
    with pytest.raises(ValueError, match="unknown parameter `foo`"):
        sillage.ptv(frames, foo=1)
    with pytest.raises(ValueError, match="detector__filter or tracker__filter"):
        sillage.ptv(frames, filter="dog")
    with pytest.raises(ValueError, match="scale_px"):
        sillage.batch(frames, scale_px=-1.0)
    with pytest.raises(ValueError, match="preprocess.medain"):
        sillage.ptv(frames, params={"preprocess.medain": 3})
    # Spelled out in every accepted way, the same key has the same effect.
    a = sillage.ptv(frames, tracker__filter=False)
    b = sillage.ptv(frames, params={"tracker": {"filter": False}})
    pd.testing.assert_frame_equal(a, b)
    fixed = sillage.batch(frames, threshold={"fixed": 0.5})
    assert len(fixed) < len(sillage.batch(frames))


def test_progress_bar_counts_frames(vortex, capsys):
    frames, _ = vortex
    sillage.batch(frames, progress=True)
    assert "8/8" in capsys.readouterr().err


def test_ptv_iter_streams_what_ptv_returns(vortex, tmp_path):
    frames, _ = vortex
    whole = sillage.ptv(frames, motion_av=5)
    steps = list(sillage.ptv_iter(iter(frames), motion_av=5))
    # The default warm-up (10 frames, more than these 8) holds every point to the end.
    assert len(steps) == len(frames) + 1
    assert all(len(s) == 0 for s in steps[:-1])
    streamed = pd.concat(steps, ignore_index=True)
    pd.testing.assert_frame_equal(streamed, whole, check_dtype=False)
    # Without it, velocities fitted over 7 frames: frame 1 leaves at frame 4, the last ones
    # at the end.
    cold = {"motion_av": 5, "warm_up_frames": 0}
    steps = list(sillage.ptv_iter(iter(frames), **cold))
    assert len(steps) == len(frames) + 1
    assert all(len(s) == 0 for s in steps[:4]) and set(steps[4].frame) == {1}
    pd.testing.assert_frame_equal(pd.concat(steps, ignore_index=True),
                                  sillage.ptv(frames, **cold), check_dtype=False)
    # With TracTrac's three-frame velocities, frame t-1 leaves as soon as frame t is seen.
    steps = list(sillage.ptv_iter(iter(frames), velocity_window=3, **cold))
    assert len(steps) == len(frames)
    assert len(steps[0]) == 0 and set(steps[2].frame) == {1}
    with pytest.raises(ValueError, match="training_passes"):
        list(sillage.ptv_iter(frames, training_passes=1))
    with pytest.raises(ValueError, match="same shape"):
        list(sillage.ptv_iter([frames[0], frames[1][:50]]))
    with pytest.raises(FileNotFoundError):
        list(sillage.ptv_iter(str(tmp_path / "missing")))


def test_evaluate_scores_tracks_against_truth(vortex):
    frames, truth = vortex
    perfect = sillage.evaluate(truth, truth)
    assert perfect["clear"]["mota"] == 1.0 and perfect["identity"]["idf1"] == 1.0
    tracks = sillage.ptv(frames, motion_av=5)
    scores = sillage.evaluate(truth, tracks, match_px=1.0)
    # PTV reports frames 1..6 of 8, so at most 3/4 of the truth is found.
    assert 0.4 < scores["clear"]["recall"] <= 0.75
    assert scores["clear"]["precision"] > 0.9
    assert 0.0 < scores["hota"]["hota"] < 1.0
    # New ids in every frame: the same detections, identities lost.
    renamed = tracks.assign(particle=tracks.particle + 1_000_000 * tracks.frame)
    assert sillage.evaluate(truth, renamed)["identity"]["idf1"] < 0.5 * scores["identity"]["idf1"]
    with pytest.raises(ValueError, match="particle"):
        sillage.evaluate(truth, tracks.drop(columns="particle"))
    with pytest.raises(ValueError, match="match_px"):
        sillage.evaluate(truth, tracks, match_px=-1.0)


def test_track_bedload_follows_beads_with_states():
    rows = []
    for frame in range(30):
        rows.append((frame, 100 + 2.0 * frame, 200.0, 0))  # a moving black bead
        rows.append((frame, 300.0, 150.0, 1))  # a transparent bead at rest
    beads = pd.DataFrame(rows, columns=["frame", "x", "y", "class"])
    for tracker in ("mmpf_plus", "det"):
        tracks = sillage.track_bedload(beads, tracker=tracker, seed=1)
        assert len(tracks) == 60 and tracks.particle.nunique() == 2
        at_rest = tracks[tracks["class"] == 1]
        assert (at_rest.state == "resting").mean() > 0.9
        moving = tracks[tracks["class"] == 0]
        assert (moving.state == "resting").sum() == 0
        assert np.allclose(moving.x.to_numpy(), 100 + 2.0 * moving.frame.to_numpy(), atol=1.5)
    with pytest.raises(ValueError, match="trackr"):
        sillage.track_bedload(beads, trackr="det")


@pytest.fixture(scope="module")
def bedload():
    return sillage.synth_bedload(n_frames=20, seed=1)


def test_synth_bedload_truth_detections_and_candidates(bedload):
    truth, det, cand = bedload
    assert list(truth.columns) == ["frame", "particle", "x", "y", "vx", "vy", "state", "class"]
    assert list(det.columns) == list(cand.columns) == ["frame", "x", "y", "class", "score"]
    # One row per bead per frame: 300 black and 100 transparent beads (the defaults).
    assert sorted(truth.frame.unique()) == list(range(20))
    assert (truth.groupby("frame").size() == 400).all()
    assert (truth.groupby("frame").particle.nunique() == 400).all()
    assert (truth[truth.frame == 0].groupby("class").size() == [300, 100]).all()
    assert set(truth.state) <= {"resting", "rolling", "saltating"}
    assert {"resting", "rolling"} <= set(truth.state)
    assert set(det["class"]) == {0, 1} and set(cand["class"]) == {1}
    assert sorted(det.frame.unique()) == list(range(20))
    # Each detection lies near a true bead of its class in its frame (σ = 0.5 px), but for
    # the false positives (about 1 per frame among ~400 detections).
    near = []
    for (frame, klass), found in det.groupby(["frame", "class"]):
        true = truth[(truth.frame == frame) & (truth["class"] == klass)][["x", "y"]].to_numpy()
        xy = found[["x", "y"]].to_numpy()
        distance = np.sqrt(((xy[:, None, :] - true[None, :, :]) ** 2).sum(-1)).min(axis=1)
        near.append(distance < 3.0)
    near = np.concatenate(near)
    assert 0.99 < near.mean() < 1.0
    # Black beads are never missed; a few transparent ones are (3 % alone, more in bursts).
    assert (det[det["class"] == 0].groupby("frame").size() == 300).all()
    assert 0.85 * 20 * 100 < (det["class"] == 1).sum() < 20 * 100
    assert (cand.score >= 0.2).all() and (det[det["class"] == 0].score == 1.0).all()


def test_synth_bedload_round_trip_through_track_bedload(bedload):
    truth, det, cand = bedload
    tracks = sillage.track_bedload(det, candidates=cand, seed=1)
    scores = sillage.evaluate(truth, tracks, match_px=3.0)
    # Measured: MOTA 0.9925, IDF1 0.996 (default scene and detector, 20 frames, seed 1).
    assert scores["clear"]["mota"] > 0.9
    assert scores["identity"]["idf1"] > 0.9
    # Measured: 5 % of the track points have no state yet.
    assert (tracks.state == "unknown").mean() < 0.2


def test_synth_bedload_is_reproducible(bedload):
    again = sillage.synth_bedload(n_frames=20, seed=1)
    for a, b in zip(bedload, again):
        pd.testing.assert_frame_equal(a, b)
    other = sillage.synth_bedload(n_frames=20, seed=2)
    for a, b in zip(bedload, other):
        assert not a.equals(b)


def test_synth_bedload_bad_keys_and_values_raise_value_errors_naming_the_key():
    with pytest.raises(ValueError, match="parameter `bogus`"):
        sillage.synth_bedload(bogus=1)
    with pytest.raises(ValueError, match="parameter `not_a_key`"):
        sillage.synth_bedload(detection={"not_a_key": 1.0})
    with pytest.raises(ValueError, match="parameter `n_frames`"):
        sillage.synth_bedload(n_frames=-3)
    with pytest.raises(ValueError, match="parameter `position_sigma_px`"):
        sillage.synth_bedload(n_frames=2, detection={"position_sigma_px": -1.0})
    with pytest.raises(ValueError, match="parameter `transition_probabilities`"):
        sillage.synth_bedload(transition_probabilities=[[2.0, 0, 0], [0, 1, 0], [0, 0, 1]])


DATA = pathlib.Path(__file__).resolve().parents[4] / "shared" / "data"
BEADS = DATA / "bedload_beads_lafaye2018"
PETS = DATA / "pets09_s2l1" / "img1"


@pytest.mark.parametrize("tracker, source, keywords, frames", [
    ("ptv", DATA / "trackpy_bulk_water" / "frames",
     {"polarity": "dark", "scale_px": 4.0}, 6),
    ("bedload", BEADS / "images",
     {"sequence_params": BEADS / "sequence_param.txt", "mask": BEADS / "sequence_base_mask.tif"},
     5),
    ("immpf", PETS, {"models": ["cv", "ca"]}, 40),
    ("siftpf", PETS, {}, 30),
])
def test_track_runs_every_tracker_on_real_frames_repeatably(tracker, source, keywords, frames):
    tracks = sillage.track(source, tracker, max_frames=frames, seed=2, **keywords)
    assert len(tracks) > 0 and tracks.particle.nunique() > 0
    assert tracks.frame.between(0, frames - 1).all()
    assert not tracks.duplicated(["particle", "frame"]).any()
    assert np.isfinite(tracks[["x", "y"]].to_numpy()).all()
    if tracker in ("immpf", "siftpf"):
        boxes = tracks[["bb_left", "bb_top", "bb_width", "bb_height"]].to_numpy()
        assert np.isfinite(boxes).all() and (boxes[:, 2:] > 0).all()
        # The point of a person is the foot of the box.
        foot_y = tracks.bb_top + tracks.bb_height
        assert np.allclose(tracks.y, foot_y)
    if tracker == "bedload":
        assert set(tracks.state) <= {"resting", "rolling", "saltating", "unknown"}
        assert set(tracks["class"]) <= {0, 1}
    again = sillage.track(source, tracker, max_frames=frames, seed=2, **keywords)
    pd.testing.assert_frame_equal(tracks, again)


@pytest.mark.parametrize("detector, source, keywords", [
    ("blob", DATA / "trackpy_bulk_water" / "frames", {"polarity": "dark", "scale_px": 4.0}),
    # OpenPIV's real image pair: 8-bit BMP, size and polarity measured.
    ("blob", DATA / "piv_openpiv_test1", {}),
    ("bead", BEADS / "images",
     {"sequence_params": BEADS / "sequence_param.txt", "mask": BEADS / "sequence_base_mask.tif"}),
    ("motion", PETS, {"min_blob_px": 200}),
])
def test_detect_runs_every_detector_on_real_frames(detector, source, keywords):
    found = sillage.detect(source, detector, max_frames=8, **keywords)
    assert len(found) > 0 and found.frame.between(0, 7).all()
    assert np.isfinite(found[["x", "y", "signal"]].to_numpy()).all()
    if detector == "motion":
        boxes = found[["bb_left", "bb_top", "bb_width", "bb_height"]].to_numpy()
        assert (boxes[:, 2] * boxes[:, 3] >= found.signal).all()
        inside = ((found.x >= found.bb_left) & (found.x <= found.bb_left + found.bb_width))
        assert inside.all()
    if detector == "bead":
        assert set(found["class"]) == {0, 1}


def test_ptv_on_an_image_pair_warns_that_no_track_can_form():
    with pytest.warns(UserWarning, match="2 frame\\(s\\): PTV links each particle over 3 frames"):
        tracks = sillage.ptv(str(DATA / "piv_openpiv_test1"))
    assert len(tracks) == 0


def test_track_and_detect_refuse_unknown_names_and_keys_with_value_errors():
    with pytest.raises(ValueError, match="unknown tracker `kalman`"):
        sillage.track(PETS, "kalman")
    with pytest.raises(ValueError, match="unknown detector `sift`"):
        sillage.detect(PETS, "sift")
    with pytest.raises(ValueError, match="tracker.particle_count"):
        sillage.track(PETS, "immpf", particle_count=3, max_frames=2)
    with pytest.raises(ValueError, match="min_blob_pixels"):
        sillage.detect(PETS, "motion", min_blob_pixels=3, max_frames=2)
    with pytest.raises(FileNotFoundError):
        sillage.track(PETS, "siftpf", ground_plane=PETS / "missing.toml", max_frames=2)


#: The `sillage` binary `cargo test --workspace` builds (CI runs it before this package).
CLI = pathlib.Path(__file__).resolve().parents[3] / "target" / "debug" / "sillage"


def cli_scores(*args: str) -> dict:
    """The combined scores of `sillage eval mot ARGS --json`."""
    import json
    import subprocess
    if not CLI.exists():
        subprocess.run(["cargo", "build", "-p", "sillage-cli"], check=True,
                       cwd=CLI.parents[2])
    run = subprocess.run([str(CLI), "eval", "mot", *args, "--json"], check=True,
                         capture_output=True, text=True)
    return json.loads(run.stdout)["combined"]["metrics"]


def mot_table(path) -> pd.DataFrame:
    """A MOTChallenge file as a DataFrame (0-based frames, boxes as written)."""
    rows = pd.read_csv(path, header=None).iloc[:, :6]
    rows.columns = ["frame", "particle", "bb_left", "bb_top", "bb_width", "bb_height"]
    rows["frame"] -= 1
    return rows


def assert_same_scores(ours: dict, cli: dict) -> None:
    for family in ("clear", "identity", "hota"):
        for key, value in cli[family].items():
            if isinstance(value, (int, float)):
                assert ours[family][key] == pytest.approx(value, rel=1e-12, abs=1e-12), \
                    (family, key)


def test_evaluate_scores_boxes_as_the_command_line_does(tmp_path):
    tracks = sillage.track(PETS, "immpf", max_frames=40, seed=1)
    pred = tmp_path / "pred.txt"
    rows = tracks.assign(frame=tracks.frame + 1, conf=1, x=-1, y=-1, z=-1)
    rows[["frame", "particle", "bb_left", "bb_top", "bb_width", "bb_height", "conf", "x", "y",
          "z"]].to_csv(pred, header=False, index=False, float_format="%.17g")
    # The truth of the 40 frames tracked.
    truth_file = tmp_path / "gt.txt"
    rows = (PETS.parent / "gt" / "gt.txt").read_text().splitlines()
    truth_file.write_text("".join(r + "\n" for r in rows if int(r.split(",")[0]) <= 40))
    cli = cli_scores("--gt", str(truth_file), "--pred", str(pred), "--match", "iou:0.5")
    ours = sillage.evaluate(mot_table(truth_file), mot_table(pred), match="iou:0.5")
    assert ours["identity"]["idf1"] > 0 and ours["clear"]["mota"] < 1
    assert_same_scores(ours, cli)


def test_evaluate_scores_bead_discs_as_the_command_line_does(tmp_path):
    pred = tmp_path / "beads.csv"
    subprocess_args = ["track", "bedload", str(BEADS / "images"), "--sequence-params",
                       str(BEADS / "sequence_param.txt"), "--mask",
                       str(BEADS / "sequence_base_mask.tif"), "--out", str(pred)]
    import subprocess
    subprocess.run([str(CLI), *subprocess_args], check=True, capture_output=True)
    truth_file = BEADS / "ground_truth" / "trackdatatruth.csv"
    cli = cli_scores("--gt", str(truth_file), "--pred", str(pred), "--match", "disc:0.43")

    def beads(path) -> pd.DataFrame:
        return pd.read_csv(path).rename(columns={"id": "particle", "category": "class"})

    ours = sillage.evaluate(beads(truth_file), beads(pred), match="disc:0.43",
                            radius_px=[15, 10])
    assert ours["clear"]["mota"] > 0.9
    assert_same_scores(ours, cli)


def test_evaluate_scores_points_as_the_command_line_does(tmp_path):
    import subprocess
    folder = tmp_path / "vortex"
    subprocess.run([str(CLI), "synth", "vortex", "--out", str(folder), "--frames", "8",
                    "--particles", "300", "--width", "256", "--height", "256"], check=True,
                   capture_output=True)
    tracks_file = tmp_path / "tracks.csv"
    subprocess.run([str(CLI), "ptv", str(folder), "--out", str(tracks_file)], check=True,
                   capture_output=True)
    cli = cli_scores("--gt", str(folder / "truth.csv"), "--pred", str(tracks_file),
                     "--match", "dist:1")
    truth = pd.read_csv(folder / "truth.csv").rename(columns={"track_id": "particle"})
    tracks = pd.read_csv(tracks_file)
    ours = sillage.evaluate(truth, tracks, match="dist:1")
    assert 0 < ours["clear"]["mota"] <= 1
    assert_same_scores(ours, cli)


def test_evaluate_names_what_a_rule_needs():
    points = pd.DataFrame({"frame": [0], "particle": [1], "x": [1.0], "y": [2.0]})
    with pytest.raises(ValueError, match="bb_left"):
        sillage.evaluate(points, points, match="iou:0.5")
    with pytest.raises(ValueError, match="radius"):
        sillage.evaluate(points, points, match="disc:0.43")
    with pytest.raises(ValueError, match="match"):
        sillage.evaluate(points, points, match="cosine:1")


def test_fit_learns_what_the_command_line_learns_and_track_takes_it(tmp_path):
    ground = tmp_path / "ground.toml"
    plane = sillage.fit("homography", PETS.parent / "gt" / "gt.txt", out=ground)
    assert plane["boxes"] > 100 and ground.exists()
    people = sillage.track(PETS, "immpf", ground_plane=ground, max_frames=30)
    assert len(people) > 0
    prior = sillage.fit("motion-prior", PETS.parent / "gt" / "gt.txt", out=tmp_path / "p.json")
    assert prior["tracks"] > 5 and prior["width_px"] == 768
    motion = sillage.fit("bedload", BEADS / "ground_truth" / "trackdatatruth.csv")
    assert motion["tracks"] > 10 and "[motion" in motion["config"]
    assert "emission" not in motion
    # The smoother's evidence from a tracker's output (the truth's own speeds stand in).
    truth = BEADS / "ground_truth" / "trackdatatruth.csv"
    smoothed = sillage.fit("bedload", truth, tracks=truth, out=tmp_path / "bedload.toml")
    emission = smoothed["emission"]
    assert emission["resting"]["log_speed"]["mean"] < emission["saltating"]["log_speed"]["mean"]
    assert "[smoother.emission" in (tmp_path / "bedload.toml").read_text()
    with pytest.raises(ValueError, match="bedload"):
        sillage.fit("homography", PETS.parent / "gt" / "gt.txt", tracks=truth)
    with pytest.raises(ValueError, match="unknown fit"):
        sillage.fit("kalman", PETS)


def test_bench_gives_the_paper_tables_as_dataframes():
    table = sillage.bench("immpf", [PETS.parent], runs=1, models=["CV_CA"], max_frames=30)
    assert list(table.models) == ["CV_CA", "SORT", "ByteTrack"] and table.runs.iloc[0] == 1
    assert 0 <= table.median_ata.iloc[0] <= 1
    sift = sillage.bench("siftpf", [PETS.parent], runs=1, selections=["reliability"],
                         max_frames=20)
    assert list(sift.sequence) == ["pets09_s2l1", "COMBINED"]
    assert (sift.frames == 20).all()
    with pytest.raises(ValueError, match="unknown bench"):
        sillage.bench("sort", [PETS.parent])
