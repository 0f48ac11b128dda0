"""Hostile and careless input: loaders, caches, checkpoints and training (issue 21).

Each test feeds one kind of damage and checks the one-sentence error (or the
rebuild) that it now gets. The authors' format is written by
``test_original._fake_tree``; the property tests at the end generate damaged
files and check that the loader either reads them exactly or raises
:class:`DataFormatError`, nothing else.
"""
from __future__ import annotations

import os
import shutil
import socket
import subprocess
import sys
import tempfile
import textwrap
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import torch
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_original import SUBTREES, _fake_tree
from test_train import tiny_profile

import pgae_lite
from pgae_lite.cae import load_cae
from pgae_lite.config import TrainConfig, get_profile
from pgae_lite.data.dataset import DataFormatError, PGAEDataset
from pgae_lite.data.original import load_original
from pgae_lite.model.pgae import PGAE
from pgae_lite.runs import data as run_data
from pgae_lite.runs import pipeline
from pgae_lite.runs.pipeline import load_model
from pgae_lite.runs.rows import TRAININGS
from pgae_lite.sim.dataset import CorruptEpisodeError, episode_folder, generate, load_episode_file
from pgae_lite.train.checkpoint import CHECKPOINT, load_checkpoint
from pgae_lite.train.loop import NonFiniteLossError, train
from pgae_lite.util.storage import (
    LOCK_FILE,
    CorruptCheckpointError,
    FolderBusyError,
    OutputError,
    atomic_write_text,
    save_torch,
)
from pgae_lite.world.words import VOCABULARY

SAMPLE = Path("201207") / "target000000.txt"     # pattern 0: training, 100 steps
ROOT = str(Path(pgae_lite.__file__).resolve().parents[1])


def _file(root: Path, sub: str, split: str = "train") -> Path:
    return root / "target" / f"{sub}_{split}" / SAMPLE


def _set(path: Path, line: int, text: str) -> None:
    """Replace line ``line`` (from 1) of a text file."""
    lines = path.read_text().splitlines()
    lines[line - 1] = text
    path.write_text("\n".join(lines) + "\n")


def _tiny(**train):
    return tiny_profile(epochs=1, max_train_samples=8, **train)


# ------------------------------------------------------------------ the authors' files
@pytest.mark.parametrize("sub, value, message", [
    ("behavior", "nan", "finite number"),
    ("vision", "nan", "finite number"),
    ("vision_opp", "inf", "finite number"),
    ("behavior", "1e30", r"joint 1e\+30 lies outside \[-1, 2\]"),
    ("vision", "-5e4", r"visual feature -50000 lies outside \[-1000, 1000\]"),
])
def test_a_bad_value_names_its_file_line_and_column(tmp_path, sub, value, message):
    root = _fake_tree(tmp_path)
    width = 5 if sub == "behavior" else 30
    _set(_file(root, sub), 3, " ".join(["0.5"] * (width - 1) + [value]))
    with pytest.raises(DataFormatError, match=message) as e:
        load_original(root)
    assert f"{sub}_train/{SAMPLE}, line 3, column {width}" in str(e.value)


def test_one_row_short_and_another_long_is_not_shifted(tmp_path):
    root = _fake_tree(tmp_path)
    f = _file(root, "behavior")
    _set(f, 2, "0.1 0.2 0.3 0.4")                   # 4 numbers ...
    _set(f, 3, "0.1 0.2 0.3 0.4 0.5 0.6")           # ... and 6: the same total
    with pytest.raises(DataFormatError, match="line 2: expected rows of 5 numbers, f"):
        load_original(root)


@pytest.mark.parametrize("row", ["1 1" + " 0" * 21, "0.5" + " 0" * 22, "0" + " 0" * 22])
def test_a_language_row_must_be_one_hot(tmp_path, row):
    root = _fake_tree(tmp_path)
    _set(_file(root, "language"), 7, row)
    with pytest.raises(DataFormatError, match=rf"{SAMPLE}, line 7: .* must be one-hot"):
        load_original(root)


def test_a_language_file_of_another_pattern_is_named(tmp_path):
    root = _fake_tree(tmp_path)
    f = _file(root, "language")
    rows = np.loadtxt(f)
    rows[1] = np.eye(len(VOCABULARY))[VOCABULARY.index("slide")]   # pattern 0: a push
    np.savetxt(f, rows, fmt="%.6f")
    with pytest.raises(DataFormatError, match="rows 1-5: description 1 reads '<BOS"):
        load_original(root)


@pytest.mark.parametrize("change, message", [
    (lambda words: words[:20], "word 21: found the end of the file, expected 'unhurr"),
    (lambda words: [words[0], words[2], words[1], *words[3:]], "word 2: found 'blo"),
    (lambda words: words[:23], "word 24: found the end of the file, expected 'desc"),
])
def test_vocabulary_txt_is_read_and_compared(tmp_path, change, message):
    root = _fake_tree(tmp_path)
    words = (root / "vocabulary.txt").read_text().splitlines()
    (root / "vocabulary.txt").write_text("\n".join(change(words)))
    with pytest.raises(DataFormatError, match=message):
        load_original(root)
    (root / "vocabulary.txt").unlink()
    with pytest.raises(DataFormatError, match="missing .*vocabulary.txt"):
        load_original(root)


def test_real_files_copied_then_damaged(original_data, tmp_path):
    """A few of the authors' own files, copied to tmp_path: they load, then a NaN."""
    root = tmp_path / "pgae"
    root.mkdir()
    for name in ("actions.txt", "arrangements.txt", "vocabulary.txt"):
        shutil.copy(original_data / name, root / name)
    for sub in SUBTREES:
        for split, number in (("train", 0), ("test", 2)):
            name = Path(f"{sub}_{split}") / "201207" / f"target{number:06d}.txt"
            (root / "target" / name).parent.mkdir(parents=True)
            shutil.copy(original_data / "target" / name, root / "target" / name)
    data = load_original(root)
    assert len(data) == 2
    _set(_file(root, "vision"), 40, " ".join(["nan"] * 30))
    with pytest.raises(DataFormatError, match="line 40, column 1"):
        load_original(root)


def test_no_test_or_no_training_samples_is_said_where_it_matters(tmp_path, toy_short):
    train_only = load_original(_fake_tree(tmp_path / "a", numbers=(0,)))
    with pytest.raises(DataFormatError, match="no test samples .* evaluation test"):
        train_only.split("test")
    test_only = toy_short.subset(toy_short.is_test)
    with pytest.raises(DataFormatError, match="no train samples"):
        train(test_only, _tiny(), progress=False, device="cpu")


def test_non_finite_data_from_any_source_stops_training(toy_short):
    data = toy_short.subset(np.arange(len(toy_short)))
    data.vision = data.vision.copy()
    data.vision[3, 2, 7] = np.nan
    with pytest.raises(DataFormatError, match=rf"sample {data.ids[3]}, step 2: vision"):
        train(data, _tiny(), progress=False, device="cpu")


# ------------------------------------------------------------------ caches
def test_an_episode_copied_over_another_is_recorded_again(smoke_episodes):
    config, _ = smoke_episodes
    folder = episode_folder(config)
    (folder / "manifest.json").unlink()
    shutil.copy(folder / "000-0.npz", folder / "001-0.npz")
    with pytest.raises(CorruptEpisodeError, match="001-0.npz: holds episode 000-0"):
        load_episode_file(folder / "001-0.npz")
    with pytest.warns(UserWarning, match="holds episode 000-0"):
        report = generate(config, progress=False)
    assert report.recorded == report.corrupt == 1
    assert load_episode_file(folder / "001-0.npz").pattern == 1


def test_a_features_file_is_checked_before_use(toy, tmp_path):
    path = tmp_path / "features.npz"
    toy.save(path, fingerprint="abc")
    assert len(PGAEDataset.load(path, fingerprint="abc")) == len(toy)
    with pytest.raises(DataFormatError, match="made from other data or configs"):
        PGAEDataset.load(path, fingerprint="another dataset's")
    nan = replace(toy, joints=np.full_like(toy.joints, np.nan))
    nan.save(path, fingerprint="abc")                    # saved whole, digest and all
    with pytest.raises(DataFormatError, match="holds NaN"):
        PGAEDataset.load(path, fingerprint="abc")
    arrays = dict(np.load(tmp_path / "features.npz"))   # arrays swapped, digest kept
    arrays["vision"] = arrays["vision"][::-1].copy()
    np.savez(path, **arrays)
    with pytest.raises(DataFormatError, match="do not match the digest"):
        PGAEDataset.load(path, fingerprint="abc")


def test_a_bad_features_cache_is_computed_again(smoke_episodes, toy):
    smoke = get_profile("smoke")
    data = run_data.simulated_dataset(smoke, progress=False)
    [path] = run_data.cache_dir().glob("features/*.npz")
    replace(data, vision=np.full_like(data.vision, np.nan)).save(path)   # NaN, no stamp
    with pytest.warns(UserWarning, match="saved without a fingerprint"):
        again = run_data.simulated_dataset(smoke, progress=False)
    np.testing.assert_array_equal(again.vision, data.vision)
    toy.save(path, fingerprint="another dataset's")
    with pytest.warns(UserWarning, match="fingerprint \"another dataset's\""):
        again = run_data.simulated_dataset(smoke, progress=False)
    np.testing.assert_array_equal(again.vision, data.vision)


SMALL = get_profile("smoke", max_train_samples=8, batch_size=4, epochs=1)


def _cached_pgae(toy_short, monkeypatch, seed: int):
    """A tiny PGAE trained into the cache, and its checkpoint's path. (The toy dataset stands in
    for the simulated one, as in test_pipeline.)"""
    monkeypatch.setattr(pipeline, "loaded", lambda *a, **k: toy_short)
    before = set(run_data.cache_dir().glob("pgae/*/" + CHECKPOINT))
    first = pipeline.trained_model(TRAININGS["PGAE"], SMALL, seed=seed, progress=False)
    [path] = set(run_data.cache_dir().glob("pgae/*/" + CHECKPOINT)) - before
    return first, path


def test_a_damaged_cached_pgae_is_trained_again(toy_short, monkeypatch):
    first, path = _cached_pgae(toy_short, monkeypatch, seed=5)
    path.write_bytes(path.read_bytes()[:1000])
    with pytest.warns(UserWarning, match="training it again: .* truncated or damaged"):
        again = pipeline.trained_model(TRAININGS["PGAE"], SMALL, seed=5, progress=False)
    assert again.history == first.history


def test_a_cached_pgae_with_other_data_statistics_is_trained_again(toy_short, monkeypatch):
    # A model cached by a pgae_lite that scaled the data otherwise: its saved normaliser differs.
    first, path = _cached_pgae(toy_short, monkeypatch, seed=6)
    ckpt = load_checkpoint(path)
    lo, hi = ckpt["normaliser"]["vision_opposite"]
    ckpt["normaliser"]["vision_opposite"] = [lo - 1.0, hi + 1.0]
    save_torch(ckpt, path)
    with pytest.warns(UserWarning, match=r"training it again: .*\(vision_opposite\)"):
        again = pipeline.trained_model(TRAININGS["PGAE"], SMALL, seed=6, progress=False)
    assert again.history == first.history and load_checkpoint(path)["normaliser"]["vision_opposite"] == [lo, hi]


# ------------------------------------------------------------------ checkpoints
def _checkpoint(tmp_path: Path, toy_short) -> Path:
    train(toy_short, _tiny(), out_dir=tmp_path, progress=False, device="cpu")
    return tmp_path / CHECKPOINT


class Payload:
    def __reduce__(self):
        return (os.system, ("echo never run",))


@pytest.mark.parametrize("damage, message", [
    (lambda raw: raw[:len(raw) // 2], "truncated or damaged"),
    (lambda raw: b"", "it is empty"),
    (lambda raw: b"not a checkpoint at all" * 10, "not a readable checkpoint"),
])
def test_a_damaged_checkpoint_is_one_sentence(toy_short, tmp_path, damage, message):
    path = _checkpoint(tmp_path, toy_short)
    path.write_bytes(damage(path.read_bytes()))
    for load in (load_checkpoint, load_model):
        with pytest.raises(CorruptCheckpointError, match=message) as e:
            load(path)
        assert str(path) in str(e.value) and "\n" not in str(e.value)
    with pytest.raises(CorruptCheckpointError, match=message):
        train(toy_short, _tiny(), out_dir=tmp_path, progress=False, device="cpu")


def test_a_pickle_payload_is_refused_not_run(tmp_path):
    for name in ("pgae.pt", "cae.pt"):
        torch.save({"model": {}, "profile": Payload(), "config": Payload()},
                   tmp_path / name)
    with pytest.raises(CorruptCheckpointError, match="weights_only=True refuses it"):
        load_model(tmp_path / "pgae.pt")
    with pytest.raises(CorruptCheckpointError, match="not a pgae_lite CAE checkpoint"):
        load_cae(tmp_path / "cae.pt")


def test_a_checkpoint_lacking_keys_is_named(tmp_path):
    torch.save({"model": {}}, tmp_path / "c.pt")
    with pytest.raises(CorruptCheckpointError, match="lacks optimiser, generator"):
        load_checkpoint(tmp_path / "c.pt")


# --------------------------------------------------------------------------- writing
_FULL = textwrap.dedent("""
    import resource, signal, sys, torch
    from pathlib import Path
    from pgae_lite.util.storage import OutputError, save_torch
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)      # a write past it fails instead
    resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))
    try:
        save_torch({"w": torch.zeros(100_000)}, Path(sys.argv[1]))
    except OutputError as e:
        print(e)
""")


def test_a_failed_checkpoint_write_names_the_file_and_keeps_the_old_one(tmp_path):
    path = tmp_path / CHECKPOINT
    save_torch({"w": torch.ones(3)}, path)
    old = path.read_bytes()
    out = subprocess.run([sys.executable, "-c", _FULL, str(path)], capture_output=True,
                         text=True, env={**os.environ, "PYTHONPATH": ROOT})
    assert out.stdout.startswith(f"cannot write {path}: ") and "old file" in out.stdout
    assert path.read_bytes() == old
    assert [p.name for p in tmp_path.iterdir()] == [CHECKPOINT]


def test_a_full_disk_is_called_a_full_disk(tmp_path):
    """A real full disk: a 64 KiB tmpfs (needs root; skipped where none can be made)."""
    disk = tmp_path / "disk"
    disk.mkdir()
    if shutil.which("mount") is None or subprocess.run(
            ["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(disk)],
            capture_output=True).returncode:
        pytest.skip("cannot mount a small tmpfs here")
    try:
        atomic_write_text(disk / "old.json", "old")
        with pytest.raises(OutputError, match=r"ckpt.pt: the disk is full \(\d+ bytes"):
            save_torch({"w": torch.zeros(100_000)}, disk / "ckpt.pt")
        with pytest.raises(OutputError, match=r"old.json: the disk is full"):
            atomic_write_text(disk / "old.json", "x" * 200_000)
        assert (disk / "old.json").read_text() == "old"
    finally:
        subprocess.run(["umount", str(disk)], check=True)


def test_impossible_output_paths_are_one_sentence(toy_short, tmp_path):
    (tmp_path / "a_file").write_text("")
    with pytest.raises(OutputError, match="a file of that name is in the way"):
        train(toy_short, _tiny(), out_dir=tmp_path / "a_file", progress=False,
              device="cpu")
    (tmp_path / "out" / CHECKPOINT).mkdir(parents=True)
    with pytest.raises(OutputError, match="it is a folder"):
        save_torch({}, tmp_path / "out" / CHECKPOINT)
    read_only = Path("/sys/pgae-lite-test")     # no new entries in sysfs, even by root
    if Path("/sys/kernel").is_dir() and not read_only.exists():
        with pytest.raises(OutputError, match="cannot create the output folder /sys"):
            train(toy_short, _tiny(), out_dir=read_only, progress=False, device="cpu")


def test_a_second_run_in_the_same_folder_fails_clearly(toy_short, tmp_path):
    alive = os.getppid()
    (tmp_path / LOCK_FILE).write_text(f"{socket.gethostname()}:{alive}")
    with pytest.raises(FolderBusyError, match=rf"in use by another run \(.*{alive}"):
        train(toy_short, _tiny(), out_dir=tmp_path, progress=False, device="cpu")
    assert not (tmp_path / CHECKPOINT).exists()
    gone = subprocess.Popen(["true"])
    gone.wait()
    (tmp_path / LOCK_FILE).write_text(f"{socket.gethostname()}:{gone.pid}")   # stale
    train(toy_short, _tiny(), out_dir=tmp_path, progress=False, device="cpu")
    assert (tmp_path / CHECKPOINT).exists() and not (tmp_path / LOCK_FILE).exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == [CHECKPOINT]


def test_a_lock_left_by_a_dead_machine_goes_stale(toy_short, tmp_path):
    """A lock of another machine's process cannot be checked by its pid: it is alive while its holder
    touches it (a sweep's worker on a shared disk), and stale once untouched for LOCK_STALE_SECONDS."""
    from pgae_lite.util.storage import LOCK_STALE_SECONDS

    lock = tmp_path / LOCK_FILE
    lock.write_text("another-machine:4242")
    with pytest.raises(FolderBusyError, match="another-machine:4242"):
        train(toy_short, _tiny(), out_dir=tmp_path, progress=False, device="cpu")
    old = time.time() - LOCK_STALE_SECONDS - 5
    os.utime(lock, (old, old))                     # that machine died: nobody touched its lock since
    train(toy_short, _tiny(), out_dir=tmp_path, progress=False, device="cpu")
    assert (tmp_path / CHECKPOINT).exists() and not lock.exists()


# ------------------------------------------------------------------ the training API
@pytest.mark.parametrize("field, value", [
    ("batch_size", -5), ("batch_size", 0), ("epochs", -3), ("epochs", 0),
    ("max_train_samples", -10), ("max_train_samples", 0), ("batch_size", 2.5),
    ("checkpoint_every", 0)])
def test_bad_training_numbers_are_refused(field, value):
    with pytest.raises(ValueError, match=f"TrainConfig {field} must be a whole number"):
        TrainConfig(**{field: value})
    with pytest.raises(ValueError, match=f"got {value!r}"):
        get_profile("smoke", **{field: value})


def test_a_field_changed_after_construction_is_checked_by_train(toy_short):
    profile = _tiny()
    profile.train.batch_size = -5
    with pytest.raises(ValueError, match="batch_size must be a whole number >= 1; got"):
        train(toy_short, profile, progress=False, device="cpu")


def test_a_non_finite_loss_stops_training(toy_short):
    profile = _tiny()
    model = PGAE(profile.model)
    with torch.no_grad():
        next(model.parameters()).fill_(float("nan"))
    with pytest.raises(NonFiniteLossError, match=r"nan .* epoch 1, batch 1 of 2 \(sig"):
        train(toy_short, profile, progress=False, device="cpu", model=model)


# --------------------------------------------------------------------------- properties
_PROPERTY = settings(max_examples=40, deadline=None,
                     suppress_health_check=[HealthCheck.too_slow])


def _tree() -> tuple[Path, tempfile.TemporaryDirectory]:
    tmp = tempfile.TemporaryDirectory()
    return _fake_tree(Path(tmp.name), numbers=(0,)), tmp


@_PROPERTY
@given(st.lists(st.integers(0, 8), min_size=1, max_size=100))
def test_random_row_lengths_load_exactly_or_fail_clearly(widths):
    root, tmp = _tree()
    with tmp:
        f = _file(root, "behavior")
        rng = np.random.default_rng(len(widths))
        values = np.round(rng.uniform(0, 1, (len(widths), 8)), 4)
        f.write_text("".join(" ".join(f"{v:.4f}" for v in row[:w]) + "\n"
                             for row, w in zip(values, widths)))
        expected = np.array([r[:5] for r, w in zip(values, widths) if w], np.float32)
        try:
            data = load_original(root)
        except DataFormatError as e:
            assert str(f) in str(e)
            return
        assert set(widths) <= {0, 5} and len(expected) == 100
        np.testing.assert_array_equal(data.joints[0], expected)


@_PROPERTY
@given(st.integers(0, 39), st.lists(st.sampled_from([0.0, 1.0, 0.5, -1.0, 2.0]),
                                    min_size=23, max_size=23))
def test_random_language_rows_load_exactly_or_fail_clearly(line, row):
    root, tmp = _tree()
    with tmp:
        f = _file(root, "language")
        original = load_original(root).descriptions
        _set(f, line + 1, " ".join(f"{v:.1f}" for v in row))
        try:
            data = load_original(root)
        except DataFormatError as e:
            assert str(f) in str(e)
            return
        np.testing.assert_array_equal(data.descriptions, original)  # only the same row


@_PROPERTY
@given(st.sampled_from(["behavior", "vision", "vision_opp"]), st.integers(0, 99),
       st.integers(0, 29), st.sampled_from(["nan", "inf", "-inf", "1e39", "ab", "1e5"]))
def test_random_bad_values_are_named_by_line(sub, line, column, value):
    root, tmp = _tree()
    with tmp:
        f = _file(root, sub)
        rows = [r.split() for r in f.read_text().splitlines()]
        rows[line][column % len(rows[line])] = value
        f.write_text("\n".join(" ".join(r) for r in rows))
        with pytest.raises(DataFormatError, match=f"line {line + 1}"):
            load_original(root)

