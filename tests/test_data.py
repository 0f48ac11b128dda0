"""pgae_lite.data: the 144 patterns, the authors' data loader, normalisation."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import torch

from pgae_lite.data import (MAX_STEPS, whitening, DataFormatError, Normaliser, Pattern, PGAEDataset, description_text,
                            load_original)
from pgae_lite.language import ACTIONS, COLOURS, SPEEDS, VOCABULARY, equivalent_descriptions

PATTERNS = [Pattern.from_number(i) for i in range(144)]


# --------------------------------------------------------------------------- patterns
def test_144_patterns_12_arrangements_by_12_actions():
    arrangements = {(p.left, p.right) for p in PATTERNS}
    codes = {p.code for p in PATTERNS}
    assert len(arrangements) == 12 and len(codes) == 12
    assert len({((p.left, p.right), p.code) for p in PATTERNS}) == 144
    for p in PATTERNS:
        assert p.left != p.right
        group = {"red", "green", "blue"} if p.left in ("red", "green", "blue") else {"yellow", "cyan", "violet"}
        assert p.right in group                                  # both cubes from one colour group
        assert p.colour == (p.left if p.side == "L" else p.right)
        assert (p.speed == "slowly") == (p.number < 72)
    assert PATTERNS[0].code == "PUSH-L-SLOW" and (PATTERNS[0].left, PATTERNS[0].right) == ("red", "blue")
    assert PATTERNS[143].code == "SLIDE-R-FAST"


def test_pattern_number_out_of_range():
    for n in (-1, 144):
        with pytest.raises(ValueError, match="0-143"):
            Pattern.from_number(n)


def test_test_split_has_every_word_and_action_type():
    test = [p for p in PATTERNS if p.is_test]
    assert len(test) == 36
    assert {p.code for p in test} == {p.code for p in PATTERNS}          # all 12 action types
    words = {VOCABULARY[i] for p in test for alt in p.descriptions() for i in alt}
    assert words == set(VOCABULARY) - {"<BOS/EOS>"}                     # all 22 words
    assert {p.action for p in test} == set(ACTIONS)
    assert {p.colour for p in test} == set(COLOURS)
    assert {p.speed for p in test} == set(SPEEDS)


def test_pattern_descriptions():
    p = Pattern.from_number(2)                                           # SLIDE-L-SLOW, red+blue
    d = p.descriptions()
    assert d.shape == (8, 3)
    assert description_text(d[0]) == "slide red slowly"
    assert [tuple(description_text(r).split()) for r in d] == equivalent_descriptions("slide", "red", "slowly")


def test_patterns_match_authors_files(original_data):
    actions = [line.split() for line in (original_data / "actions.txt").read_text().splitlines() if line.strip()]
    arrangements = [line.strip() for line in (original_data / "arrangements.txt").read_text().splitlines()
                    if line.strip()]
    assert len(actions) == len(arrangements) == 144
    for p, (code, split), arr in zip(PATTERNS, actions, arrangements):
        assert p.code == code
        assert f"{p.left}+{p.right}" == arr
        assert p.is_test == (split == "test")


# --------------------------------------------------------------------------- the authors' data
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


def test_split(original):
    train, test = original.split("train"), original.split("test")
    assert len(train) == 648 and len(test) == 216
    assert not train.is_test.any() and test.is_test.all()
    with pytest.raises(ValueError, match="train, test"):
        original.split("validation")
    assert 0 < original.joint_range() <= 1.0 + 1e-6                         # joints scaled to [0, 1]


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
    for name in ("actions.txt", "arrangements.txt"):
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


# --------------------------------------------------------------------------- normalisation
def test_normaliser_maps_train_to_unit_range(toy):
    train = toy.split("train")
    norm = Normaliser.fit(train)
    t = norm.tensors(train)
    m = torch.from_numpy(train.mask)
    for key in ("joints", "vision", "vision_opposite"):
        x = t[key]
        assert x.dtype == torch.float32
        valid = x[m]
        assert float(valid.min()) == pytest.approx(-1.0, abs=1e-5)
        assert float(valid.max()) == pytest.approx(1.0, abs=1e-5)
        assert (x[~m] == 0).all()                                        # padded steps are 0
    assert t["lengths"].dtype == torch.int64 and t["descriptions"].shape == (108, 8, 3)


def test_normaliser_uses_only_the_data_it_is_fitted_on(toy):
    """Statistics come from the split passed in: changing test samples changes nothing."""
    train = toy.split("train")
    altered = toy.subset(np.arange(len(toy)))
    altered.joints = altered.joints.copy()
    altered.joints[altered.is_test] += 10.0
    assert Normaliser.fit(altered.split("train")) == Normaliser.fit(train)
    assert Normaliser.fit(altered) != Normaliser.fit(train)


def test_normaliser_padding_ignored_in_statistics(toy):
    """Padded zeros must not count as data: fit uses valid steps only."""
    shifted = toy.subset(np.arange(len(toy)))
    shifted.joints = np.where(shifted.mask[..., None], shifted.joints + 5.0, 0.0).astype(np.float32)
    lo, hi = Normaliser.fit(shifted).joints
    assert lo > 4.0 and hi > lo


def test_normaliser_state_dict_round_trip(toy):
    norm = Normaliser.fit(toy.split("train"))
    state = json.loads(json.dumps(norm.state_dict()))                    # JSON-safe
    assert Normaliser.from_state_dict(state) == norm


def test_whitening_decorrelates_the_training_features(toy):
    train = toy.split("train")
    norm = Normaliser.fit(train, "whiten")
    assert norm.whitening is not None and Normaliser.fit(train).whitening is None
    x = train.vision[train.mask]                                                 # (steps, 30)
    mean, W = whitening(x)
    z = (x - mean) @ W
    lam = np.linalg.eigvalsh(np.cov(x.astype(np.float64), rowvar=False))     # variances along the principal axes
    np.testing.assert_allclose(np.linalg.eigvalsh(np.cov(z, rowvar=False)),   # after: λ / (λ + ε λmax), all <= 1
                               np.sort(lam / (lam + 0.01 * lam.max())), atol=1e-6)
    valid = norm.tensors(train)["vision"][torch.from_numpy(train.mask)]
    assert float(valid.min()) == pytest.approx(-1.0, abs=1e-5) and float(valid.max()) == pytest.approx(1.0, abs=1e-5)
    np.testing.assert_allclose(norm.vision_to_model(x), valid.numpy(), atol=1e-6)   # the same map, one step
    assert norm.joints == Normaliser.fit(train).joints                          # joints as before
    def unscaled(opposite):                                                      # undo the min/max: the whitened z
        lo, hi = norm.vision_opposite if opposite else norm.vision
        return (norm.vision_to_model(x, opposite) + 1) / 2 * (hi - lo) + lo
    np.testing.assert_allclose(unscaled(True), unscaled(False), atol=1e-4)      # one whitening for both views
    state = json.loads(json.dumps(norm.state_dict()))
    assert Normaliser.from_state_dict(state) == norm
    with pytest.raises(ValueError, match="global, whiten"):
        Normaliser.fit(train, "per_feature")


def test_joints_to_data_inverts(toy):
    norm = Normaliser.fit(toy.split("train"))
    t = norm.tensors(toy)
    back = norm.joints_to_data(t["joints"])
    assert isinstance(back, torch.Tensor)
    m = toy.mask
    np.testing.assert_allclose(back.numpy()[m], toy.joints[m], atol=1e-5)
    back_np = norm.joints_to_data(t["joints"].numpy())
    np.testing.assert_allclose(back_np[m], toy.joints[m], atol=1e-5)


def test_tensors_on_device(toy):
    t = Normaliser.fit(toy).tensors(toy, "cpu")
    assert all(v.device.type == "cpu" for v in t.values())


def test_subset_and_mask(toy):
    assert isinstance(toy, PGAEDataset) and len(toy) == 144
    s = toy.subset(np.array([0, 2, 5]))
    assert len(s) == 3 and s.ids.tolist() == [toy.ids[i] for i in (0, 2, 5)]
    assert toy.mask.shape == (144, MAX_STEPS)
    assert (toy.mask.sum(1) == toy.lengths).all()
    # Toy data has the paper's structure.
    assert set(toy.lengths.tolist()) == {50, 100}
    assert int(toy.is_test.sum()) == 36
    assert all(np.array_equal(toy.descriptions[i], Pattern.from_number(int(toy.pattern[i])).descriptions())
               for i in range(len(toy)))


def test_dataset_save_load_round_trip_and_damage(tmp_path):
    from pgae_lite.data import DataFormatError, PGAEDataset
    from pgae_lite.toydata import toy_dataset

    ds = toy_dataset()
    path = tmp_path / "ds.npz"
    ds.save(path)
    back = PGAEDataset.load(path)
    for k in ("joints", "vision", "vision_opposite", "lengths", "descriptions", "pattern", "is_test", "ids",
              "action", "arrangement"):
        np.testing.assert_array_equal(getattr(back, k), getattr(ds, k))
    assert back.source == ds.source
    raw = bytearray(path.read_bytes())
    raw[len(raw) // 2] ^= 0xFF                                       # one flipped byte
    path.write_bytes(bytes(raw[: len(raw) - 100]))                  # ... and a truncated file
    with pytest.raises(DataFormatError, match="not a readable PGAE dataset"):
        PGAEDataset.load(path)
