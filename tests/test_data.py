"""pgae_lite.data.dataset: the dataset type, its split, saving and loading, normalisation."""
from __future__ import annotations

import json

import numpy as np
import pytest
import torch

from pgae_lite.data.dataset import PGAEDataset
from pgae_lite.data.normaliser import Normaliser, whitening
from pgae_lite.world.patterns import MAX_STEPS, Pattern


# --------------------------------------------------------------------------- the dataset
def test_split(original):
    train, test = original.split("train"), original.split("test")
    assert len(train) == 648 and len(test) == 216
    assert not train.is_test.any() and test.is_test.all()
    with pytest.raises(ValueError, match="train, test"):
        original.split("validation")
    assert 0 < original.joint_range() <= 1.0 + 1e-6                         # joints scaled to [0, 1]


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
    assert norm.vision_opposite == norm.vision                                  # one scale for both views:
    np.testing.assert_array_equal(norm.vision_to_model(x, True), norm.vision_to_model(x))   # one picture, one z
    opp = norm.tensors(train)["vision_opposite"][torch.from_numpy(train.mask)]
    np.testing.assert_allclose(norm.vision_to_model(train.vision_opposite[train.mask], True), opp.numpy(), atol=1e-6)
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
    from pgae_lite.data.dataset import DataFormatError, PGAEDataset
    from pgae_lite.data.toy import toy_dataset

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
