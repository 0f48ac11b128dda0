"""pgae_lite.data.original: the authors' data loader (the real tree, and synthetic trees in its format)."""
from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from pgae_lite.data.dataset import DataFormatError
from pgae_lite.data.original import load_original
from pgae_lite.world.patterns import Pattern
from pgae_lite.world.words import SIGNALS, VOCABULARY


def test_load_original(original):
    d = original
    assert len(d) == 864
    assert int((~d.is_test).sum()) == 648 and int(d.is_test.sum()) == 216
    assert set(d.lengths.tolist()) == {50, 100}
    assert d.joints.shape == (864, 100, 5)
    assert d.vision.shape == d.vision_opposite.shape == (864, 100, 30)
    assert d.descriptions.shape == (864, 8, 3)
    pad = ~d.mask
    assert (d.joints[pad] == 0).all() and (d.vision[pad] == 0).all() and (d.vision_opposite[pad] == 0).all()
    assert "201207/target000002" in set(d.ids.tolist())
    assert all(len(i) == len("201207/target000002") and i[6:13] == "/target" for i in d.ids)
    assert len(set(d.ids.tolist())) == 864
    assert list(d.ids) == sorted(d.ids)
    # 6 recordings of each pattern; fast ones last 50 steps.
    assert np.bincount(d.pattern, minlength=144).tolist() == [6] * 144
    for i in range(0, 864, 37):
        p = Pattern.from_number(int(d.pattern[i]))
        assert np.array_equal(d.descriptions[i], p.descriptions())
        assert d.is_test[i] == p.is_test
        assert d.action[i] == p.code and d.arrangement[i] == f"{p.left}+{p.right}"
        assert d.lengths[i] == (100 if p.speed == "slowly" else 50)
        assert int(d.ids[i][-6:]) == p.number


SUBTREES = ("behavior", "vision", "vision_opp", "language")


def _language_rows(pattern: Pattern) -> np.ndarray:
    """The authors' language file: 8 alternatives x 5 one-hot rows (<BOS/EOS> w1 w2 w3 <BOS/EOS>)."""
    tokens = [[0, *alt, 0] for alt in pattern.descriptions()]
    return np.eye(len(VOCABULARY))[np.array(tokens).reshape(-1)]                   # (40, 23)


def _fake_tree(dest: Path, numbers=(0, 2), date="201207") -> Path:
    """A tiny synthetic tree in the authors' format: actions.txt, arrangements.txt and, for each
    pattern number, one sample (``target/{sub}_{split}/DATE/targetNNNNNN.txt``)."""
    root = dest / "pgae"
    root.mkdir(parents=True)
    patterns = [Pattern.from_number(i) for i in range(144)]
    (root / "actions.txt").write_text("".join(
        f"{p.code:<23}{'test' if p.is_test else 'train'}\n" for p in patterns))
    (root / "arrangements.txt").write_text("".join(f"{p.left}+{p.right}\n" for p in patterns))
    words = [*VOCABULARY, *(f"{s}:" for s in SIGNALS)]
    (root / "vocabulary.txt").write_text("\n".join(words))
    for sub in SUBTREES:
        for split in ("train", "test"):
            (root / "target" / f"{sub}_{split}" / date).mkdir(parents=True)
    rng = np.random.default_rng(0)
    for number in numbers:
        p = patterns[number]
        split, steps = ("test" if p.is_test else "train"), (100 if p.speed == "slowly" else 50)
        arrays = {"behavior": rng.uniform(0, 1, (steps, 5)), "vision": rng.uniform(0, 1, (steps, 30)),
                  "vision_opp": rng.uniform(0, 1, (steps, 30)), "language": _language_rows(p)}
        for sub, a in arrays.items():
            np.savetxt(root / "target" / f"{sub}_{split}" / date / f"target{number:06d}.txt", a, fmt="%.6f")
    return root


def test_fake_tree_loads(tmp_path):
    root = _fake_tree(tmp_path, numbers=(0, 2, 80))
    d = load_original(root)
    assert list(d.ids) == ["201207/target000000", "201207/target000002", "201207/target000080"]
    assert d.is_test.tolist() == [False, True, True]
    assert d.lengths.tolist() == [100, 100, 50]
    assert (d.joints[2, 50:] == 0).all() and d.joints.shape == (3, 100, 5)
    for i, n in enumerate((0, 2, 80)):
        assert np.array_equal(d.descriptions[i], Pattern.from_number(n).descriptions())
    assert load_original(root / "target").ids.tolist() == d.ids.tolist()   # the target/ folder itself works too


def test_fake_tree_has_the_authors_format(original_data, tmp_path):
    """The synthetic files above follow the real ones (same language rows, same shapes)."""
    root = _fake_tree(tmp_path)
    for split, number in (("train", 0), ("test", 2)):
        name = f"201207/target{number:06d}.txt"
        real = np.loadtxt(original_data / "target" / f"language_{split}" / name)
        np.testing.assert_array_equal(real, np.loadtxt(root / "target" / f"language_{split}" / name))
        for sub in SUBTREES[:3]:
            real = np.loadtxt(original_data / "target" / f"{sub}_{split}" / name)
            assert real.shape == np.loadtxt(root / "target" / f"{sub}_{split}" / name).shape
    for name in ("actions.txt", "arrangements.txt", "vocabulary.txt"):
        real = [line.split() for line in (original_data / name).read_text().splitlines() if line.strip()]
        assert real == [line.split() for line in (root / name).read_text().splitlines()]


def test_loader_missing_folder(tmp_path):
    with pytest.raises(DataFormatError, match="target/") as e:
        load_original(tmp_path / "nowhere")
    assert "oo222bs/PGAE" in str(e.value)


def test_loader_folder_without_target(tmp_path):
    (tmp_path / "actions.txt").write_text("")
    with pytest.raises(DataFormatError, match="expected a folder containing 'target/'"):
        load_original(tmp_path)


def test_loader_missing_subtree(tmp_path):
    root = _fake_tree(tmp_path)
    shutil.rmtree(root / "target" / "vision_opp_test")
    with pytest.raises(DataFormatError, match="vision_opp_test"):
        load_original(root)


def test_loader_missing_actions_file(tmp_path):
    root = _fake_tree(tmp_path)
    (root / "actions.txt").unlink()
    with pytest.raises(DataFormatError, match="actions.txt"):
        load_original(root)


def test_loader_malformed_row_width(tmp_path):
    root = _fake_tree(tmp_path)
    (root / "target" / "behavior_train" / "201207" / "target000000.txt").write_text("0.1 0.2 0.3\n")
    with pytest.raises(DataFormatError, match="expected rows of 5 numbers"):
        load_original(root)


def test_loader_malformed_text(tmp_path):
    root = _fake_tree(tmp_path)
    f = root / "target" / "vision_train" / "201207" / "target000000.txt"
    f.write_text("not numbers at all\n")
    with pytest.raises(DataFormatError, match="target000000"):
        load_original(root)


def test_loader_missing_file(tmp_path):
    root = _fake_tree(tmp_path)
    (root / "target" / "language_test" / "201207" / "target000002.txt").unlink()
    with pytest.raises(DataFormatError, match="language_test"):
        load_original(root)


def test_loader_step_count_mismatch(tmp_path):
    root = _fake_tree(tmp_path)
    f = root / "target" / "vision_train" / "201207" / "target000000.txt"
    f.write_text("\n".join(f.read_text().splitlines()[:-1]))
    with pytest.raises(DataFormatError, match="same number of steps"):
        load_original(root)


def test_loader_language_rows(tmp_path):
    root = _fake_tree(tmp_path)
    f = root / "target" / "language_train" / "201207" / "target000000.txt"
    f.write_text("\n".join(f.read_text().splitlines()[:35]))
    with pytest.raises(DataFormatError, match="40 one-hot rows"):
        load_original(root)


def test_loader_sample_in_wrong_split(tmp_path):
    root = _fake_tree(tmp_path)
    for sub in SUBTREES:
        src = root / "target" / f"{sub}_train" / "201207" / "target000000.txt"
        shutil.move(src, root / "target" / f"{sub}_test" / "201207" / src.name)
    with pytest.raises(DataFormatError, match="actions.txt puts pattern 0 in train"):
        load_original(root)


def test_loader_empty_tree(tmp_path):
    root = _fake_tree(tmp_path, numbers=())
    with pytest.raises(DataFormatError, match="no samples"):
        load_original(root)
