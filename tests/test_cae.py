"""The channel-separated CAE: shapes, input convention, training, determinism, checkpoints."""
from __future__ import annotations

import numpy as np
import pytest
import torch

from pgae_lite.cae import (
    CAEConfig,
    ChannelSeparatedCAE,
    as_input,
    extract_features,
    load_cae,
    reconstruct,
    train_cae,
)
from pgae_lite.config import PROFILES, get_profile
from pgae_lite.util.storage import CheckpointMismatchError

TINY = CAEConfig("tiny", batch_size=4, iterations=3, seed=0)


def squares(n: int, seed: int = 0) -> np.ndarray:
    """(n, 120, 160, 3) uint8: a flat grey background with two coloured squares at random places."""
    rng = np.random.default_rng(seed)
    images = np.full((n, 120, 160, 3), 120, np.uint8)
    colours = np.array([[220, 30, 30], [30, 200, 40], [40, 60, 220], [230, 220, 40]], np.uint8)
    for img in images:
        for c in rng.choice(len(colours), 2, replace=False):
            y, x = rng.integers(0, 120 - 24), rng.integers(0, 160 - 24)
            img[y:y + 24, x:x + 24] = colours[c]
    return images


@pytest.fixture(scope="module")
def images() -> np.ndarray:
    return squares(64)


@pytest.fixture(scope="module")
def model() -> ChannelSeparatedCAE:
    torch.manual_seed(0)
    return ChannelSeparatedCAE().eval()


def test_shapes(model, images):
    x = images[:5]
    feats = model.encode(x)
    assert feats.shape == (5, 30) and feats.abs().max() <= 1          # tanh features [R10, G10, B10]
    rec = model(x)
    assert rec.shape == (5, 3, 120, 160) and 0 <= rec.min() and rec.max() <= 1
    assert model.red.conv(as_input(x)[:, :1]).shape == (5, 64, 3, 4)  # 64 x 3 x 4 = 768
    assert reconstruct(model, x).shape == (5, 120, 160, 3) and reconstruct(model, x).dtype == np.uint8


def test_both_layouts_and_dtypes_agree(model, images):
    x = images[:3]
    nchw = torch.from_numpy(x).permute(0, 3, 1, 2).float() / 255      # (B, 3, 120, 160) float
    with torch.no_grad():
        torch.testing.assert_close(model.encode(x), model.encode(nchw))


@pytest.mark.parametrize("bad, message", [
    (np.zeros((120, 160, 3), np.uint8), "add a batch axis"),
    (np.zeros((2, 120, 160, 4), np.uint8), r"\(B, 120, 160, 3\)"),
    (np.zeros((2, 3, 160, 120), np.uint8), r"\(B, 3, 120, 160\)"),
    (np.zeros((2, 60, 80, 3), np.uint8), "got"),
    (np.zeros((2, 120, 160, 3), np.int64), "uint8"),
    (np.full((2, 120, 160, 3), 200.0, np.float32), r"\[0, 1\]"),
])
def test_wrong_input_is_refused(model, bad, message):
    with pytest.raises(ValueError, match=message):
        model.encode(bad)


def test_extract_features_streams_and_equals_encode(images):
    torch.manual_seed(0)
    model = ChannelSeparatedCAE()
    model.loss(images[:16])[0].backward()    # a training-mode pass: BatchNorm statistics move off their defaults
    model.eval()
    feats = extract_features(model, images[:37], batch=16)                # 16 + 16 + 5
    assert feats.shape == (37, 30) and feats.dtype == np.float32
    with torch.no_grad():
        np.testing.assert_allclose(feats, model.encode(images[:37]).numpy(), atol=1e-5)
    assert extract_features(model, images[:0]).shape == (0, 30)
    model.train()
    extract_features(model, images[:2])
    assert model.training                                                 # its mode is left as it was


def test_each_colour_has_its_own_ten_features(model, images):
    a = images[:4].copy()
    b = a.copy()
    b[:, 40:80, 60:100, 0] = 255                                          # change the red channel only
    fa, fb = extract_features(model, a), extract_features(model, b)
    assert np.abs(fa[:, :10] - fb[:, :10]).max() > 1e-3                   # red features move
    np.testing.assert_array_equal(fa[:, 10:], fb[:, 10:])                 # green and blue do not


def test_training_lowers_the_loss(images):
    config = CAEConfig("test", batch_size=8, iterations=40)
    _, history = train_cae(images, config, progress=False)
    assert len(history) == 40 and set(history[0]) == {"iteration", "loss", "red", "green", "blue"}
    x = np.clip(images / 255.0, 1e-6, 1 - 1e-6)
    floor = -np.mean(x * np.log(x) + (1 - x) * np.log(1 - x))  # BCE of a perfect copy (not 0 for grey)
    first = np.mean([h["loss"] for h in history[:5]]) - floor
    last = np.mean([h["loss"] for h in history[-5:]]) - floor
    assert last < 0.5 * first, (first, last)


def test_training_is_deterministic(images):
    a, ha = train_cae(images[:16], TINY, progress=False)
    b, hb = train_cae(images[:16], TINY, progress=False)
    c, _ = train_cae(images[:16], CAEConfig("tiny", batch_size=4, iterations=3, seed=1), progress=False)
    assert ha == hb
    for (name, p), q in zip(a.state_dict().items(), b.state_dict().values()):
        assert torch.equal(p, q), name
    assert not torch.equal(a.red.fc[0].weight, c.red.fc[0].weight)


def test_the_callers_thread_count_does_not_change_the_weights(images, set_threads):
    """Trained on 1 and on 2 torch threads, a CAE is the same (utils.training_threads); without the
    fixed count the convolutions' sums add in other orders and the weights differ after a few steps."""
    config = CAEConfig("tiny", batch_size=32, iterations=4, seed=0)
    weights = []
    for threads in (1, 2):
        set_threads(threads)
        model, _ = train_cae(images, config, device="cpu", progress=False)
        weights.append(model.state_dict())
        assert torch.get_num_threads() == threads          # the caller's count is back
    for name, p in weights[0].items():
        assert torch.equal(p, weights[1][name]), name


def test_checkpoint_round_trip_and_refusals(images, tmp_path):
    path = tmp_path / "cae.pt"
    model, history = train_cae(images[:16], TINY, progress=False, out_path=path)
    assert path.exists() and not list(tmp_path.glob("*.tmp"))
    again, history2 = train_cae(images[:16], TINY, progress=False, out_path=path)  # loaded, not retrained
    assert history2 == history
    for p, q in zip(model.state_dict().values(), again.state_dict().values()):
        assert torch.equal(p, q)
    loaded, ckpt = load_cae(path, model.device)   # the same device: CPU and CUDA round differently
    np.testing.assert_array_equal(extract_features(loaded, images[:4]), extract_features(model, images[:4]))
    assert ckpt["config"]["name"] == "tiny" and not loaded.training
    with pytest.raises(CheckpointMismatchError, match="different config"):
        train_cae(images[:16], CAEConfig("tiny", batch_size=4, iterations=3, seed=1), progress=False, out_path=path)
    with pytest.raises(CheckpointMismatchError, match="different set of images"):
        train_cae(images[16:32], TINY, progress=False, out_path=path)


def test_train_cae_wants_uint8_frames(images):
    with pytest.raises(ValueError, match="uint8"):
        train_cae(images[:4] / 255.0, TINY, progress=False)


def test_profiles(monkeypatch):
    paper = PROFILES["paper"].cae
    assert paper == CAEConfig()                                   # the authors' recipe
    assert (paper.features, paper.conv, paper.hidden) == (10, (8, 16, 32, 64), (384, 192))
    assert (paper.lr, paper.batch_size, paper.iterations) == (1e-3, 200, 10_000)
    book = PROFILES["book"].cae
    assert (book.name, book.batch_size, book.iterations, book.frame_stride) == ("book", 16, 1000, 10)
    monkeypatch.setenv("PGAE_LITE_PROFILE", "smoke")
    assert get_profile().cae == PROFILES["smoke"].cae
    with pytest.raises(ValueError, match="unknown profile 'fast'"):
        get_profile("fast")
    assert CAEConfig.from_dict(paper.to_dict()) == paper


def test_train_cae_wants_a_config(images):
    with pytest.raises(TypeError, match="CAEConfig"):
        train_cae(images[:4], "smoke", progress=False)


def test_extraction_works_without_batchnorm():
    """A student's variant with BatchNorm removed (an exercise) still extracts features."""
    import torch.nn as nn

    from pgae_lite.cae import CAEConfig, ChannelSeparatedCAE, extract_features

    model = ChannelSeparatedCAE(CAEConfig("smoke")).eval()
    for ae in (model.red, model.green, model.blue):
        ae.conv = nn.Sequential(*[nn.Identity() if isinstance(m, nn.BatchNorm2d) else m for m in ae.conv])
    images = np.random.default_rng(0).integers(0, 256, (3, 120, 160, 3), dtype=np.uint8)
    with torch.no_grad():
        expected = model.encode(images)
    np.testing.assert_allclose(extract_features(model, images), expected.numpy(), atol=1e-5)
