"""Hostile input, round three (issue 62, points 4 and 5): every command's folders are checked before any work,
a read-only cache is read, and every saved file (the family's models included) goes through one set of load
checks. Each test feeds one input of the report and asserts the one-sentence answer or the correct handling."""
from __future__ import annotations

import errno
import math
import os
import pathlib
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
import torch

from pgae_lite.__main__ import main
from pgae_lite.util.checks import output_folder
from pgae_lite.util.errors import PGAELiteError
from pgae_lite.util.storage import (
    CheckpointMismatchError,
    CorruptCheckpointError,
    OutputError,
    SavedFileNotFoundError,
    atomic_folder,
    folder_lock,
    load_torch,
    make_folder,
)

ROOT = Path(__file__).resolve().parents[1]


def refused(argv: list[str], capsys) -> str:
    """The command line's one message for ``argv`` (exit status 2, no traceback; after a usage line for an
    argument, alone for an error of the package)."""
    try:
        status = main(argv)
    except SystemExit as e:
        status = e.code
    err = capsys.readouterr().err
    assert status == 2 and "Traceback" not in err, err
    return err.strip().splitlines()[-1]


@pytest.fixture
def dangling(tmp_path) -> Path:
    link = tmp_path / "gone"
    link.symlink_to(tmp_path / "nowhere")
    return link


@pytest.fixture
def foreign(tmp_path) -> Path:
    folder = tmp_path / "mine"
    folder.mkdir()
    (folder / "thesis.tex").write_text("keep me")
    return folder


# --------------------------------------------------------------------------- 1. every command's folders
def test_export_web_to_an_unset_variable_is_refused_and_writes_nothing(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert "OUT is empty text (an unset variable?)" in refused(["export-web", ""], capsys)
    assert list(tmp_path.iterdir()) == []                  # was: the whole playground in the current folder


def test_export_web_to_a_file_is_refused(tmp_path, capsys):
    (tmp_path / "f").write_text("x")
    assert "is a file, not a folder" in refused(["export-web", str(tmp_path / "f")], capsys)


def test_export_web_to_a_dangling_link_says_so(dangling, capsys):
    message = refused(["export-web", str(dangling)], capsys)
    assert "is a dangling link (to " in message and "in the way" not in message


def test_export_web_into_someone_elses_folder_is_refused(foreign, capsys):
    assert "did not make: it holds files it did not write (thesis.tex)" in refused(["export-web", str(foreign)],
                                                                                  capsys)
    assert (foreign / "thesis.tex").read_text() == "keep me"


def test_reproduce_to_a_dangling_link_says_so(dangling, capsys):
    message = refused(["reproduce", "--out", str(dangling), "--no-progress"], capsys)
    assert "--out" in message and "is a dangling link" in message and "in the way" not in message


def test_make_folder_through_a_dangling_link_says_so(dangling):
    with pytest.raises(OutputError, match="is a dangling link .* remove the link"):
        make_folder(dangling / "sub")


def test_a_cache_through_a_dangling_link_says_so(dangling, monkeypatch):
    from pgae_lite.util.storage import cache_dir

    monkeypatch.setenv("PGAE_LITE_CACHE", str(dangling))
    with pytest.raises(OutputError, match=r"\(PGAE_LITE_CACHE\) cannot be used: .* is a dangling link"):
        cache_dir()


def test_reproduce_into_someone_elses_folder_is_refused(foreign, capsys):
    assert "that reproduce did not make" in refused(["reproduce", "--out", str(foreign), "--no-progress"], capsys)


def test_reproduce_resumes_in_a_folder_it_wrote(tmp_path):
    out = tmp_path / "run"
    for name in ("PGAE-seed0", "logs"):
        (out / name).mkdir(parents=True)
    (out / "results.json").write_text("{}")
    (out / ".pgae_lite.lock.123-0123abcd").write_text("")
    from pgae_lite.runs.reproduce import WRITES as REPRODUCE_WRITES

    assert output_folder("--out", out, "reproduce", written=REPRODUCE_WRITES) == out.resolve()


def test_a_file_on_the_way_to_the_folder_is_refused(tmp_path, capsys):
    (tmp_path / "f").write_text("x")
    assert "cannot be made: " in refused(["export-web", str(tmp_path / "f" / "web")], capsys)


def test_a_nul_character_in_a_folder_is_one_sentence(capsys):
    assert "holds a NUL character" in refused(["export-web", "web\0x"], capsys)


def test_student_edition_to_an_unset_variable_is_refused(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert "folder is empty text (an unset variable?)" in refused(["student-edition", " "], capsys)
    assert list(tmp_path.iterdir()) == []


def test_student_edition_reads_no_missing_executed_folder(tmp_path, dangling, capsys):
    assert "--executed" in refused(["student-edition", str(tmp_path / "s"), "--executed", ""], capsys)
    assert "no such folder" in refused(["student-edition", str(tmp_path / "s"), "--executed",
                                        str(tmp_path / "none")], capsys)
    assert "dangling link" in refused(["student-edition", str(tmp_path / "s"), "--executed", str(dangling)], capsys)
    assert not (tmp_path / "s").exists()


def test_course_prepare_to_a_dangling_link_says_so(dangling, capsys):
    assert "is a dangling link" in refused(["course", "prepare", str(dangling)], capsys)


def test_course_prepare_into_someone_elses_folder_is_refused(foreign, capsys):
    assert "that course prepare did not make" in refused(["course", "prepare", str(foreign)], capsys)


def test_course_assign_to_a_dangling_link_says_so(dangling, capsys):
    assert "is a dangling link" in refused(["course", "assign", str(dangling)], capsys)


@pytest.fixture
def course(tmp_path) -> tuple[Path, Path]:
    """A course folder with an autograder file, and a folder of submissions."""
    (tmp_path / "course" / "autograder").mkdir(parents=True)
    (tmp_path / "course" / "autograder" / "ps1.zip").write_bytes(b"")
    (tmp_path / "subs").mkdir()
    return tmp_path / "course", tmp_path / "subs"


@pytest.mark.parametrize("timeout", ["inf", "nan", "-1", "0"])
def test_course_grade_refuses_a_timeout_that_is_not_a_positive_number(course, tmp_path, timeout, capsys):
    args = ["course", "grade", "ps1", str(course[1]), "--course", str(course[0]), "--report", str(tmp_path / "r")]
    assert "--timeout must be a finite number > 0" in refused(args + ["--timeout", timeout], capsys)
    assert not (tmp_path / "r").exists()


def test_course_grade_refuses_a_report_through_a_dangling_link(course, dangling, capsys):
    args = ["course", "grade", "ps1", str(course[1]), "--course", str(course[0]), "--report", str(dangling)]
    assert "--report" in (message := refused(args, capsys)) and "dangling link" in message


def test_course_grade_refuses_a_report_inside_the_submissions(course, capsys):
    args = ["course", "grade", "ps1", str(course[1]), "--course", str(course[0]), "--report", str(course[1] / "r")]
    assert "is inside the submissions folder" in refused(args, capsys)


def test_course_grade_refuses_an_assignment_name_that_is_a_path(course, tmp_path, capsys):
    args = ["course", "grade", "../course/autograder/ps1", str(course[1]), "--course", str(course[0]),
            "--report", str(tmp_path / "r")]
    assert "is not an assignment's name" in refused(args, capsys)


def test_course_grade_refuses_missing_submissions(course, tmp_path, capsys):
    args = ["course", "grade", "ps1", "", "--course", str(course[0]), "--report", str(tmp_path / "r")]
    assert "SUBMISSIONS is empty text" in refused(args, capsys)


# --------------------------------------------------------------------------- 2. a read-only cache
def read_only(monkeypatch, folder: Path) -> None:
    """Emulate a read-only disk under ``folder`` (the tests run as root, whom chmod does not stop): every write,
    link, rename, removal or touch there raises OSError(EROFS), as a read-only mount does."""
    folder = Path(folder).resolve()

    def inside(path) -> bool:
        path = Path(os.fspath(path)).resolve()
        return path == folder or folder in path.parents

    def guard(original, *positions):
        def wrapped(*args, **kwargs):
            for i in positions:
                if i < len(args) and isinstance(args[i], (str, os.PathLike)) and inside(args[i]):
                    raise OSError(errno.EROFS, "Read-only file system", str(args[i]))
            return original(*args, **kwargs)
        return wrapped

    for name in ("write_text", "write_bytes", "unlink", "touch"):
        monkeypatch.setattr(pathlib.Path, name, guard(getattr(pathlib.Path, name), 0))
    monkeypatch.setattr(os, "link", guard(os.link, 0, 1))
    monkeypatch.setattr(os, "replace", guard(os.replace, 0, 1))
    monkeypatch.setattr(os, "utime", guard(os.utime, 0))


def test_a_lock_that_cannot_be_written_lets_the_folder_be_read(tmp_path, monkeypatch):
    read_only(monkeypatch, tmp_path)
    with folder_lock(tmp_path) as held:      # was: OSError(EROFS) from the clean-up, outside its handler
        assert held is False
    assert list(tmp_path.iterdir()) == []


def _tiny_profile(epochs: int = 1):
    from pgae_lite.config import get_profile

    return get_profile("smoke", epochs=epochs, max_train_samples=8, batch_size=8, checkpoint_every=1)


def test_a_finished_model_in_a_read_only_folder_is_loaded(toy_short, tmp_path, monkeypatch):
    from pgae_lite.train.loop import train

    trained = train(toy_short, _tiny_profile(), out_dir=tmp_path, progress=False, device="cpu")
    before = sorted(tmp_path.iterdir())
    read_only(monkeypatch, tmp_path)
    again = train(toy_short, _tiny_profile(), out_dir=tmp_path, progress=False, device="cpu")
    assert all(torch.equal(a, b) for a, b in zip(trained.model.state_dict().values(),
                                                 again.model.state_dict().values()))
    assert sorted(tmp_path.iterdir()) == before


def test_an_unfinished_model_in_a_read_only_folder_is_one_sentence(toy_short, tmp_path, monkeypatch):
    from pgae_lite.train.checkpoint import CHECKPOINT
    from pgae_lite.train.loop import train

    train(toy_short, _tiny_profile(2), out_dir=tmp_path, progress=False, device="cpu")
    _alter(tmp_path / CHECKPOINT, lambda c: c.__setitem__("epoch", 1))        # as a run stopped after epoch 1
    read_only(monkeypatch, tmp_path)
    with pytest.raises(OutputError, match=r"cannot be written .* not finished \(1 of the recipe's 2 epochs"):
        train(toy_short, _tiny_profile(2), out_dir=tmp_path, progress=False, device="cpu")


_READ_ONLY_MOUNT = textwrap.dedent("""
    import sys
    import numpy as np
    from pgae_lite.config import get_profile
    from pgae_lite.data.toy import toy_dataset
    from pgae_lite.train.loop import train
    data = toy_dataset(variations=1)
    for name in ("joints", "vision", "vision_opposite"):
        setattr(data, name, np.ascontiguousarray(getattr(data, name)[:, ::10]))
    data.lengths = -(-data.lengths // 10)
    profile = get_profile("smoke", epochs=1, max_train_samples=8, batch_size=8)
    print(float(next(iter(train(data, profile, out_dir=sys.argv[1], progress=False, device="cpu")
                          .model.parameters())).sum()))
""")


def test_a_finished_model_on_a_real_read_only_mount_is_loaded(tmp_path):
    """The same on a read-only bind mount in a private mount namespace (needs root and unshare; skipped
    where they are missing)."""
    if shutil.which("unshare") is None or subprocess.run(
            ["unshare", "-m", "sh", "-c", f"mount --bind {tmp_path} {tmp_path}"], capture_output=True).returncode:
        pytest.skip("cannot make a read-only bind mount here")
    env = {**os.environ, "PYTHONPATH": str(ROOT), "OMP_NUM_THREADS": "1"}
    first = subprocess.run([sys.executable, "-c", _READ_ONLY_MOUNT, str(tmp_path)], capture_output=True, text=True,
                           env=env)
    assert first.returncode == 0, first.stderr[-2000:]
    mount = f"mount --bind {tmp_path} {tmp_path} && mount -o remount,ro,bind {tmp_path} && "
    again = subprocess.run(["unshare", "-m", "sh", "-c", mount + f'"{sys.executable}" -c "$0" {tmp_path}',
                            _READ_ONLY_MOUNT], capture_output=True, text=True, env=env)
    assert again.returncode == 0, again.stderr[-2000:]
    assert again.stdout == first.stdout


def test_a_failed_export_leaves_no_half_written_folder(tmp_path, monkeypatch, capsys):
    def fails_midway(out, *args, **kwargs):
        (Path(out) / "models").mkdir()
        (Path(out) / "models" / "PGAE.onnx").write_bytes(b"half")
        raise OutputError("cannot write /cache/x: Read-only file system")

    monkeypatch.setattr("pgae_lite.web.assets.export_web", fails_midway)
    monkeypatch.setenv("PGAE_LITE_PROFILE", "smoke")
    assert main(["export-web", str(tmp_path / "web"), "--no-progress"]) == 2
    assert "Read-only file system" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []                 # no web/, no temporary sibling


def test_an_export_over_its_own_folder_replaces_its_files_and_keeps_the_rest(tmp_path):
    out = tmp_path / "web"
    with atomic_folder(out) as staging:
        (staging / "manifest.json").write_text("old")
        (staging / "models").mkdir()
    (out / "notes.txt").write_text("mine")
    with atomic_folder(out) as staging:
        (staging / "manifest.json").write_text("new")
        (staging / "models").mkdir()
        (staging / "models" / "a.onnx").write_text("graph")
    assert (out / "manifest.json").read_text() == "new" and (out / "models" / "a.onnx").is_file()
    assert (out / "notes.txt").read_text() == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["web"]


# --------------------------------------------------------------------------- 3. one set of load checks
@pytest.fixture
def family_model(toy_short, tmp_path) -> tuple[Path, object]:
    """A family row's model (PRAE) trained and saved as every model is: OUT/PRAE-seed0/checkpoint.pt."""
    from pgae_lite.runs.rows import TRAININGS
    from pgae_lite.train.checkpoint import CHECKPOINT
    from pgae_lite.train.loop import train

    prof = TRAININGS["PRAE"].profile(_tiny_profile())
    path = tmp_path / "PRAE-seed0" / CHECKPOINT
    train(toy_short, prof, out_dir=path.parent, progress=False, device="cpu")
    return path, prof


def _alter(path: Path, change) -> None:
    ckpt = torch.load(path, weights_only=True)
    change(ckpt)
    torch.save(ckpt, path)


def test_a_family_model_with_nan_weights_is_refused(family_model, toy_short):
    from pgae_lite.runs.pipeline import load_model
    from pgae_lite.train.loop import train

    path, prof = family_model
    name = next(k for k, v in torch.load(path, weights_only=True)["model"].items() if v.is_floating_point())
    _alter(path, lambda c: c["model"][name].fill_(math.nan))
    with pytest.raises(CorruptCheckpointError, match=rf"non-finite weights \(NaN or infinite\) in model.{name}"):
        train(toy_short, prof, out_dir=path.parent, progress=False, device="cpu")   # was: evaluated, null cells
    with pytest.raises(CorruptCheckpointError, match="non-finite weights"):
        load_model(path, device="cpu")


def test_nan_in_the_optimiser_state_is_refused(family_model, toy_short):
    from pgae_lite.train.loop import train

    path, prof = family_model

    def poison(ckpt):
        state = next(iter(ckpt["optimiser"]["state"].values()))
        state["exp_avg"].fill_(math.inf)
    _alter(path, poison)
    with pytest.raises(CorruptCheckpointError, match=r"non-finite values .* in optimiser.state"):
        train(toy_short, prof, out_dir=path.parent, progress=False, device="cpu")


def test_a_family_model_missing_a_tensor_names_it(family_model, toy_short):
    from pgae_lite.runs.pipeline import load_model
    from pgae_lite.train.loop import train

    path, prof = family_model
    name = sorted(torch.load(path, weights_only=True)["model"])[-1]
    _alter(path, lambda c: c["model"].pop(name))
    with pytest.raises(CheckpointMismatchError, match=rf"lacks the tensor\(s\) {name}"):
        train(toy_short, prof, out_dir=path.parent, progress=False, device="cpu")   # was: a raw RuntimeError
    with pytest.raises(CheckpointMismatchError, match=rf"do not fit the model .*lacks the tensor\(s\) {name}"):
        load_model(path, device="cpu")


def test_a_folder_where_the_family_model_should_be_is_one_sentence(toy_short, tmp_path):
    from pgae_lite.train.checkpoint import CHECKPOINT
    from pgae_lite.train.loop import train

    (tmp_path / CHECKPOINT).mkdir()
    with pytest.raises(CorruptCheckpointError, match="is a folder where a checkpoint .* should be"):
        train(toy_short, _tiny_profile(), out_dir=tmp_path, progress=False, device="cpu")
    assert (tmp_path / CHECKPOINT).is_dir()                # refused, not removed


def test_a_missing_saved_file_is_one_of_the_packages_errors(tmp_path):
    with pytest.raises(SavedFileNotFoundError, match="no checkpoint at"):
        load_torch(tmp_path / "none.pt")
    assert issubclass(SavedFileNotFoundError, PGAELiteError) and issubclass(SavedFileNotFoundError,
                                                                            FileNotFoundError)


def test_a_model_config_with_an_unknown_key_names_it(family_model):
    from pgae_lite.runs.pipeline import load_model

    path, _ = family_model
    _alter(path, lambda c: c["profile"]["model"].__setitem__("attention_heads", 8))
    with pytest.raises(CheckpointMismatchError, match=r"the model's settings this pgae_lite does not know "
                                                      r"\(attention_heads"):
        load_model(path, device="cpu")                  # was: TypeError: unexpected keyword argument


def test_a_model_config_with_a_wrong_value_is_one_sentence(family_model):
    from pgae_lite.runs.pipeline import load_model

    path, _ = family_model
    _alter(path, lambda c: c["profile"]["model"].__setitem__("hidden", "wide"))
    with pytest.raises(CheckpointMismatchError, match="the model's settings this pgae_lite refuses"):
        load_model(path, device="cpu")


def test_a_family_model_of_another_recipe_version_is_refused_by_the_one_reader(family_model):
    from pgae_lite.train.checkpoint import load_checkpoint
    from pgae_lite.train.config import RECIPE_VERSION

    path, _ = family_model
    _alter(path, lambda c: c["profile"].__setitem__("recipe_version", RECIPE_VERSION + 1))
    with pytest.raises(CheckpointMismatchError, match=f"trained with recipe version {RECIPE_VERSION + 1}"):
        load_checkpoint(path)


@pytest.fixture
def cae_file(tmp_path) -> Path:
    from pgae_lite.cae import CAEConfig, train_cae

    images = np.random.default_rng(0).integers(0, 255, (4, 120, 160, 3), dtype=np.uint8)
    path = tmp_path / "cae.pt"
    train_cae(images, CAEConfig(iterations=1, batch_size=2), "cpu", progress=False, out_path=path)
    return path


def test_a_cae_with_nan_weights_is_refused(cae_file):
    from pgae_lite.cae import load_cae

    _alter(cae_file, lambda c: next(v for v in c["model"].values() if v.is_floating_point()).fill_(math.nan))
    with pytest.raises(CorruptCheckpointError, match=f"{cae_file.name} holds non-finite weights"):
        load_cae(cae_file, "cpu")


def test_a_cae_missing_a_tensor_names_it(cae_file):
    from pgae_lite.cae import load_cae

    name = sorted(torch.load(cae_file, weights_only=True)["model"])[0]
    _alter(cae_file, lambda c: c["model"].pop(name))
    with pytest.raises(CheckpointMismatchError, match=rf"do not fit the CAE .*lacks the tensor\(s\) {name}"):
        load_cae(cae_file, "cpu")


def test_a_cae_config_with_an_unknown_key_names_it(cae_file):
    from pgae_lite.cae import load_cae

    _alter(cae_file, lambda c: c["config"].__setitem__("dropout", 0.1))
    with pytest.raises(CheckpointMismatchError, match=r"CAE settings this pgae_lite does not know \(dropout"):
        load_cae(cae_file, "cpu")


# --------------------------------------------------------------------------- 4. --pretrained-model
def test_the_pretrained_model_reaches_pvae_berts_encoder(tmp_path, monkeypatch):
    from pgae_lite.bert.transformer import model_source
    from pgae_lite.config import get_profile
    from pgae_lite.runs.rows import ROWS

    seen = {}
    monkeypatch.setattr("pgae_lite.runs.reproduce.reproduce", lambda *a: seen.update(rows=a[7], model=a[9]))
    folder = model_source(None)                     # the default model's folder, named as a user would name one
    assert main(["reproduce", "--rows", "PVAE-BERT,PVAE-BERT-tuned", "--pretrained-model", folder,
                 "--out", str(tmp_path / "o"), "--no-progress"]) == 0
    for row in seen["rows"]:
        prof = ROWS[row].training.profile(get_profile("smoke"), 864, seen["model"])
        assert prof.model.language.model == folder, row


def test_the_pretrained_models_help_names_every_row_that_reads_one(capsys):
    from pgae_lite.runs.rows import ROWS

    readers = [r for r in ROWS if "language" in ROWS[r].training.model]
    with pytest.raises(SystemExit):
        main(["reproduce", "--help"])
    shown = " ".join(capsys.readouterr().out.split())
    help_text = shown.split("--pretrained-model NAME")[-1].split("--epochs", 1)[0]
    assert readers and all(r in help_text for r in readers), (readers, help_text)


def test_the_pretrained_model_without_a_row_that_reads_it_is_refused(tmp_path, capsys):
    message = refused(["reproduce", "--rows", "PVAE", "--pretrained-model", "x", "--out", str(tmp_path / "o")],
                      capsys)
    assert "but no row (PVAE) reads it" in message
