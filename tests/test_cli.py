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
from pgae_lite.world.words import TEST_SIGNALS

ROOT = Path(__file__).resolve().parents[1]
OPTIONS = ("--original-data", "--profile", "--rows", "--seed", "--seeds", "--pretrained-model", "--epochs", "--out",
           "--device", "--no-progress")


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
    for row in ("PGAE-BERT", "PGAE-self", "PGAE-opposite"):
        assert row in rep.stdout


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


def _check_outputs(out: Path, original, row: str = "PGAE", seeds: tuple[int, ...] = (0,)) -> dict:
    report = json.loads((out / "results.json").read_text())
    assert report["profile"] == "smoke" and report["seeds"] == list(seeds)
    assert report["wall_seconds"] > 0
    for info in report["trainings"].values():
        assert set(info["train_seconds"]) == {str(s) for s in seeds}
        assert all(t > 0 for t in info["train_seconds"].values())
    cells = report["rows"][row]
    for seed in seeds:
        assert list(cells["seeds"][str(seed)]) == list(TEST_SIGNALS)
    for signal in TEST_SIGNALS:
        for seed in seeds:
            cell = cells["seeds"][str(seed)][signal]
            assert 0 <= cell["accuracy"] <= 100 and cell["nrmse"] > 0 and cell["n"] == 216
        assert set(cells["paper"][signal]) == {"accuracy", "nrmse"}
        assert set(cells["mean"][signal]) == set(cells["std"][signal]) == {"accuracy", "nrmse", "nrmse_padded"}

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
    assert {p.name for p in out.iterdir()} == {"PGAE-seed0", "results.json", "predictions.npz"}
    assert {p.name for p in (out / "PGAE-seed0").iterdir()} == {"checkpoint.pt", "predictions-PGAE.npz"}
    assert (out / "predictions.npz").read_bytes() == (out / "PGAE-seed0" / "predictions-PGAE.npz").read_bytes()
    first = _check_outputs(out, original)
    checkpoint = (out / "PGAE-seed0" / "checkpoint.pt").read_bytes()

    # A second run in the same folder finds the finished checkpoint: no training, same results.
    # (In this process, with the already-loaded data, to keep the suite fast: same code path.)
    monkeypatch.setenv("PGAE_LITE_PROFILE", "smoke")
    monkeypatch.setattr("pgae_lite.data.original.load_original", lambda path: original)
    assert main(["reproduce", "--original-data", str(original_data), "--out", str(out), "--no-progress",
                 "--device", "cpu"]) == 0
    assert (out / "PGAE-seed0" / "checkpoint.pt").read_bytes() == checkpoint  # no epoch was run again
    second = _check_outputs(out, original)
    assert second["rows"] == first["rows"]
    capsys.readouterr()

    # Another recipe in the same folder is refused with a clear message.
    assert main(["reproduce", "--original-data", str(original_data), "--out", str(out), "--epochs", "4",
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
    assert len(ids) == report["rows"]["PGAE"]["seeds"]["0"]["execute"]["n"] and all(i.startswith("sim/") for i in ids)


def test_reproduce_self_and_opposite_rows_over_two_seeds(original_data, original, tmp_path, monkeypatch, capsys):
    """One model trained on both views gives two rows; two seeds give mean ± std of every cell."""
    monkeypatch.setenv("PGAE_LITE_PROFILE", "smoke")
    monkeypatch.setattr("pgae_lite.data.original.load_original", lambda path: original)
    out = tmp_path / "views"
    assert main(["reproduce", "--original-data", str(original_data), "--out", str(out), "--rows",
                 "pgae-self,PGAE-opposite", "--seeds", "2", "--no-progress", "--device", "cpu"]) == 0
    printed = capsys.readouterr().out
    assert "80.56" in printed and "65.28" in printed and "±" in printed      # both paper rows, mean ± std
    assert {p.name for p in out.iterdir()} == {"PGAE-views-seed0", "PGAE-views-seed1", "results.json",
                                               "predictions.npz", "logs"}
    assert len(list((out / "logs").glob("table1-*.log"))) == 2     # two units, side by side: a log each
    for seed in (0, 1):
        assert {p.name for p in (out / f"PGAE-views-seed{seed}").iterdir()} == {
            "checkpoint.pt", "predictions-PGAE-self.npz", "predictions-PGAE-opposite.npz"}
    report = _check_outputs(out, original, "PGAE-opposite", seeds=(0, 1))
    _check_outputs(out, original, "PGAE-self", seeds=(0, 1))
    assert report["trainings"]["PGAE-views"]["profile"]["train"]["opposite_prob"] == 0.5
    rows = report["rows"]
    for seed in ("0", "1"):
        for shared in ("execute", "repeat language"):           # no action shown: the same cells
            assert rows["PGAE-opposite"]["seeds"][seed][shared] == rows["PGAE-self"]["seeds"][seed][shared]
        assert rows["PGAE-opposite"]["seeds"][seed]["describe"] != rows["PGAE-self"]["seeds"][seed]["describe"]
    cells = [rows["PGAE-self"]["seeds"][s]["describe"]["nrmse"] for s in ("0", "1")]
    assert rows["PGAE-self"]["mean"]["describe"]["nrmse"] == pytest.approx(np.mean(cells))
    assert rows["PGAE-self"]["std"]["describe"]["nrmse"] == pytest.approx(np.std(cells, ddof=1))


def test_unknown_row_and_bad_seed_count_are_clear_errors(capsys):
    with pytest.raises(SystemExit) as e:
        main(["reproduce", "--rows", "PGAE,GPT"])
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert "'GPT'" in err and "PGAE-BERT" in err and "PGAE-opposite" in err
    with pytest.raises(SystemExit):
        main(["reproduce", "--seeds", "0"])
    assert "--seeds must be a whole number from 1 to 100" in capsys.readouterr().err


def test_cli_profile_names_match_the_package():
    import pgae_lite.config as config
    from pgae_lite.__main__ import FAMILY_ROW_NAMES, PROFILE_ENV, PROFILE_NAMES, ROW_NAMES
    from pgae_lite.config import PROFILES
    from pgae_lite.runs.rows import FAMILY_ROWS, ROWS, TABLE1_ROWS

    assert tuple(PROFILES) == PROFILE_NAMES == config.PROFILE_NAMES
    assert PROFILE_ENV == config.PROFILE_ENV and ROW_NAMES == tuple(TABLE1_ROWS)
    assert FAMILY_ROW_NAMES == tuple(FAMILY_ROWS) and ROW_NAMES + FAMILY_ROW_NAMES == tuple(ROWS)


def test_help_does_not_import_torch():
    """--help stays instant: the CLI keeps its own copies of the profile and row names (checked above)."""
    code = ("import sys\nfrom pgae_lite.__main__ import main\ntry:\n    main(['reproduce', '--help'])\n"
            "except SystemExit:\n    pass\nprint('torch' in sys.modules, 'pgae_lite.config' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.splitlines()[-1] == "False False"


@pytest.mark.parametrize("command", ["simulate", "reproduce", "export-web"])
def test_unknown_profile_in_the_environment_is_one_clear_line(command):
    folder = ["out"] if command == "export-web" else []                # export-web's one positional argument
    r = run(command, *folder, "--no-progress", env={"PGAE_LITE_PROFILE": "garbage"}, timeout=120)
    assert r.returncode == 2 and r.stdout == ""
    assert r.stderr.splitlines() == ["error: unknown profile 'garbage' (from the environment variable "
                                     "PGAE_LITE_PROFILE); the profiles are: smoke, book, paper"]


def test_unknown_profile_option_is_refused_by_the_parser(capsys):
    with pytest.raises(SystemExit) as e:
        main(["simulate", "--profile", "garbage"])
    assert e.value.code == 2 and "invalid choice: 'garbage'" in capsys.readouterr().err


def test_export_web_writes_what_the_books_build_writes(smoke_episodes, tmp_path, monkeypatch, capsys):
    """``export-web``: the playground's models, episodes and manifest, from the cache (smoke profile)."""
    pytest.importorskip("onnxruntime")
    monkeypatch.setenv("PGAE_LITE_PROFILE", "smoke")
    out = tmp_path / "web"
    assert main(["export-web", str(out), "--no-simulator", "--no-progress", "--float32"]) == 0
    assert capsys.readouterr().out.startswith("live playground: 3 models and ")
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["profile"] == "smoke" and manifest["sim_runs"] is None and not (out / "sim_runs.json").exists()
    assert manifest["free_text"]["weights"] == "float32" and manifest["free_text"]["bytes"] > 80e6
    for entry in manifest["models"].values():
        assert (out / entry["file"]).stat().st_size == entry["bytes"]
    from matplotlib.image import imread

    for episode in manifest["episodes"]:                          # NICO's recorded camera, first and last step
        for which in ("first", "last"):
            name = manifest["frames"].format(episode=episode["id"].removeprefix("sim/"), which=which)
            assert imread(out / name).shape[:2] == (120, 160)
