"""python -m pgae_lite: help, reproduce (smoke profile) on the authors' data, errors."""
from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pgae_lite.__main__ import main
from pgae_lite.language import TEST_SIGNALS

ROOT = Path(__file__).resolve().parents[1]
OPTIONS = ("--original-data", "--profile", "--seed", "--epochs", "--out", "--device", "--no-progress")


def run(*args, env=None, timeout=300):
    environ = {k: v for k, v in os.environ.items() if k != "PGAE_ORIGINAL_DATA"}
    environ.update({"PGAE_LITE_PROFILE": "smoke", "OMP_NUM_THREADS": "1"}, **(env or {}))
    return subprocess.run([sys.executable, "-m", "pgae_lite", *map(str, args)], cwd=ROOT, env=environ,
                          capture_output=True, text=True, timeout=timeout)


def test_help():
    rep = run("reproduce", "--help")                               # the real entry point, in a new process
    assert rep.returncode == 0
    for option in OPTIONS:
        assert option in rep.stdout, option
    for profile in ("smoke", "book", "paper"):
        assert profile in rep.stdout
    assert "PGAE_ORIGINAL_DATA" in rep.stdout and "PGAE_LITE_PROFILE" in rep.stdout


def test_top_level_help(capsys):
    with pytest.raises(SystemExit) as e:
        main(["--help"])
    assert e.value.code == 0
    assert "reproduce" in capsys.readouterr().out


def test_missing_data_path(tmp_path):
    missing = tmp_path / "no-such-folder"
    r = run("reproduce", "--original-data", missing, "--out", tmp_path / "out", "--no-progress")
    assert r.returncode == 2
    assert str(missing) in r.stderr and "target/" in r.stderr and "oo222bs/PGAE" in r.stderr
    assert "Traceback" not in r.stderr


def _check_outputs(out: Path, original) -> dict:
    report = json.loads((out / "results.json").read_text())
    assert report["profile"]["name"] == "smoke" and report["seed"] == 0
    assert report["wall_seconds"] > 0 and report["train_seconds"] > 0
    assert list(report["results"]) == list(TEST_SIGNALS)
    for signal in TEST_SIGNALS:
        cell = report["results"][signal]
        assert 0 <= cell["accuracy"] <= 100 and cell["nrmse"] > 0 and cell["n"] == 216
        assert set(report["paper"][signal]) == {"accuracy", "nrmse"}

    with np.load(out / "predictions.npz", allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    keys = {f"{s.replace(' ', '_')}_{part}" for s in TEST_SIGNALS for part in ("ids", "text", "joints")}
    assert set(arrays) == keys
    test = original.split("test")
    for s in ("describe", "repeat_language", "execute", "repeat_action"):
        ids, text, joints = arrays[f"{s}_ids"], arrays[f"{s}_text"], arrays[f"{s}_joints"]
        assert ids.shape == text.shape == (216,)
        assert all(re.fullmatch(r"\d{6}/target\d{6}", i) for i in ids)
        assert list(ids) == list(test.ids)
        assert joints.shape == (216, 100, 5)
        for k in range(0, 216, 17):
            n = test.lengths[k]
            assert not np.isnan(joints[k, :n]).any() and np.isnan(joints[k, n:]).all()
    return report


def test_reproduce_smoke_and_resume(original_data, original, tmp_path, monkeypatch, capsys):
    out = tmp_path / "run"
    r = run("reproduce", "--original-data", original_data, "--out", out, "--no-progress", "--device", "cpu")
    assert r.returncode == 0, r.stderr
    assert "93.05" in r.stdout and "paper PGAE" in r.stdout            # Table 1 beside the paper's row
    assert {p.name for p in out.iterdir()} == {"checkpoint.pt", "results.json", "predictions.npz"}
    first = _check_outputs(out, original)
    checkpoint = (out / "checkpoint.pt").read_bytes()

    # A second run in the same folder finds the finished checkpoint: no training, same results.
    # (In this process, with the already-loaded data, to keep the suite fast: same code path.)
    monkeypatch.setenv("PGAE_LITE_PROFILE", "smoke")
    monkeypatch.setattr("pgae_lite.data.load_original", lambda path: original)
    assert main(["reproduce", "--original-data", str(original_data), "--out", str(out), "--no-progress",
                 "--device", "cpu"]) == 0
    assert (out / "checkpoint.pt").read_bytes() == checkpoint           # no epoch was run again
    second = _check_outputs(out, original)
    assert second["results"] == first["results"]
    assert second["final_loss"] == first["final_loss"]
    capsys.readouterr()

    # Another seed in the same folder is refused with a clear message.
    assert main(["reproduce", "--original-data", str(original_data), "--out", str(out), "--seed", "1",
                 "--no-progress", "--device", "cpu"]) == 2
    assert "different profile" in capsys.readouterr().err

def test_simulate_and_reproduce_on_simulated_data(smoke_episodes, tmp_path, monkeypatch, capsys):
    """Without --original-data the whole pipeline runs on our simulator's data (smoke profile)."""
    monkeypatch.delenv("PGAE_ORIGINAL_DATA", raising=False)
    monkeypatch.setenv("PGAE_LITE_PROFILE", "smoke")
    assert main(["simulate", "--no-progress"]) == 0
    assert "24 episodes" in capsys.readouterr().out                 # already recorded by the fixture
    out = tmp_path / "sim-run"
    assert main(["reproduce", "--out", str(out), "--no-progress", "--device", "cpu"]) == 0
    assert "paper PGAE" in capsys.readouterr().out
    report = json.loads((out / "results.json").read_text())
    assert report["data"].startswith("simulated:")
    with np.load(out / "predictions.npz", allow_pickle=False) as z:
        assert {k for k in z.files} == {f"{s.replace(' ', '_')}_{part}" for s in TEST_SIGNALS
                                        for part in ("ids", "text", "joints")}
        ids = z["execute_ids"]
    assert len(ids) == report["results"]["execute"]["n"] and all(i.startswith("sim/") for i in ids)


def test_cli_profile_names_match_the_package():
    from pgae_lite.__main__ import PROFILE_NAMES
    from pgae_lite.config import PROFILES

    assert tuple(PROFILES) == PROFILE_NAMES
