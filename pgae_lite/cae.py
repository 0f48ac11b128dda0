"""Channel-separated convolutional autoencoder: visual features (paper Sec. 3, "Action Encoder").

The action encoder does not see raw pixels. Each 120x160 RGB frame is first
compressed by a *channel-separated* convolutional autoencoder (CAE): one small
autoencoder per colour channel, so the red, green and blue images are encoded
independently, and the three 10-d bottlenecks are concatenated:

    v_t = [E_R(x_t^R); E_G(x_t^G); E_B(x_t^B)]  in R^30

Each autoencoder is trained to rebuild its channel, pixel by pixel, with binary
cross-entropy (pixels in [0, 1]):

    BCE(x, x̂) = −mean(x · log x̂ + (1 − x) · log(1 − x̂)),   x̂ = sigmoid(decoder(E(x)))

Sizes follow the authors' code: conv channels 8-16-32-64, fully connected
768-384-192-10, Adam 1e-3, batch 200, 10,000 iterations (the ``paper`` profile).

Profiles (``pgae_lite.config``, each profile's ``cae``): ``smoke`` (seconds), ``book``
(batch 16 x 1000 iterations: ~3.7 min on one CPU core, ~2.5 on two), ``paper`` (batch
200 x 10,000: for a GPU). Features go to the action encoder; see ``extract_features``.

Input convention (one for the whole module): a batch of images, ``uint8`` in
0..255 or float in [0, 1], laid out (B, 120, 160, 3) as a simulator or a PNG
gives them, or (B, 3, 120, 160) as torch does. Anything else raises ValueError.
"""
from __future__ import annotations

import time
import zlib
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Callable

import numpy as np
import torch
from torch import nn
from torch.nn.utils.fusion import fuse_conv_bn_eval
from tqdm.auto import tqdm

from pgae_lite.util.storage import CheckpointMismatchError, default_device, load_torch, save_torch, training_threads

HEIGHT, WIDTH = 120, 160
COLOURS = ("red", "green", "blue")


@dataclass(frozen=True)
class CAEConfig:
    """Architecture and training recipe of the channel-separated CAE (defaults: the authors')."""

    name: str = "paper"
    features: int = 10                           # bottleneck size per colour channel (x 3 = 30)
    conv: tuple[int, ...] = (8, 16, 32, 64)      # encoder channels; the decoder mirrors them
    hidden: tuple[int, ...] = (384, 192)         # fully connected layers between 768 and the bottleneck
    lr: float = 1e-3
    batch_size: int = 200
    iterations: int = 10_000
    seed: int = 0
    # Which frames to train on (used by the caller, e.g. the dataset cache): every k-th frame of
    # the training episodes, both views. 864 x ~75 x 2 frames would be 7.5 GB even as uint8.
    frame_stride: int = 4

    def to_dict(self) -> dict:
        d = asdict(self)
        return {k: list(v) if isinstance(v, tuple) else v for k, v in d.items()}

    @classmethod
    def from_dict(cls, d: dict) -> CAEConfig:
        return cls(**{k: tuple(v) if isinstance(v, list) else v for k, v in d.items()})


def _down(cin: int, cout: int, kernel: int, stride: int, pad: int) -> list[nn.Module]:
    """Conv, BatchNorm, ReLU (the conv needs no bias: BatchNorm adds one)."""
    return [nn.Conv2d(cin, cout, kernel, stride, pad, bias=False), nn.BatchNorm2d(cout), nn.ReLU(inplace=True)]


def _up(cin: int, cout: int, kernel: int, stride: int, pad: int, extra: int = 0) -> list[nn.Module]:
    """Transposed conv, BatchNorm, ReLU; ``extra`` rows/columns of output padding."""
    return [nn.ConvTranspose2d(cin, cout, kernel, stride, pad, output_padding=extra, bias=False),
            nn.BatchNorm2d(cout), nn.ReLU(inplace=True)]


class ChannelAutoencoder(nn.Module):
    """Autoencoder of one colour channel: (B, 1, 120, 160) -> 10 features -> (B, 1, 120, 160).

    Encoder: three 4x4 stride-2 convs halve the image (120x160 -> 60x80 -> 30x40
    -> 15x20), an 8x8 stride-5 conv takes 15x20 to 3x4 (as in the authors' code):
    64 x 3 x 4 = 768 numbers, then fully connected 768 -> 384 -> 192 -> 10.
    The decoder mirrors it: 10 -> 192 -> 384 -> 768, transposed convs back up.
    """

    def __init__(self, config: CAEConfig = CAEConfig()):
        super().__init__()
        if len(config.conv) != 4 or len(config.hidden) != 2:
            raise ValueError("the CAE has 4 conv layers (their strides fit 120x160) and 2 hidden fully "
                             f"connected layers; got conv={config.conv}, hidden={config.hidden}")
        c1, c2, c3, c4 = config.conv             # 8, 16, 32, 64
        h1, h2 = config.hidden                   # 384, 192
        f = config.features                      # 10
        self.map_shape = (c4, 3, 4)              # the smallest feature map
        flat = c4 * 3 * 4                        # 768
        # Deviation from paper (authors' code): BatchNorm after every conv and deconv
        # but the last. Without it our CAE sat for hundreds of iterations on the "mean
        # image" (the same blurred table for every frame, features constant), far past a
        # CPU budget; with it, arm and cube colours appear within ~300 iterations.
        self.conv = nn.Sequential(
            *_down(1, c1, 4, 2, 1),              # (B, 8, 60, 80)
            *_down(c1, c2, 4, 2, 1),             # (B, 16, 30, 40)
            *_down(c2, c3, 4, 2, 1),             # (B, 32, 15, 20)
            *_down(c3, c4, 8, 5, 2))             # (B, 64, 3, 4): (15 + 2*2 - 8) // 5 + 1 = 3
        # Deviation from paper (authors' code): ReLU between the fully connected layers
        # (authors: none, so 768-384-192-10 was one linear map in disguise) and tanh on
        # the bottleneck (authors: linear, features within about ±60). tanh keeps the
        # features in [-1, 1], the range of the LSTM's own tanh units, whatever the images.
        self.fc = nn.Sequential(
            nn.Linear(flat, h1), nn.ReLU(inplace=True),   # 768 -> 384
            nn.Linear(h1, h2), nn.ReLU(inplace=True),     # 384 -> 192
            nn.Linear(h2, f), nn.Tanh())                  # 192 -> 10, in [-1, 1]
        # Deviation from paper (authors' code): the decoder mirrors the encoder; the
        # authors' went 10-192-384 and reshaped to 32x3x4. Easier to read, same idea.
        self.unfc = nn.Sequential(
            nn.Linear(f, h2), nn.ReLU(inplace=True),      # 10 -> 192
            nn.Linear(h2, h1), nn.ReLU(inplace=True),     # 192 -> 384
            nn.Linear(h1, flat), nn.ReLU(inplace=True))   # 384 -> 768
        self.deconv = nn.Sequential(
            *_up(c4, c3, 8, 5, 2, extra=1),      # (B, 32, 15, 20): (3 - 1)*5 - 2*2 + 8 + 1 = 15
            *_up(c3, c2, 4, 2, 1),               # (B, 16, 30, 40)
            *_up(c2, c1, 4, 2, 1),               # (B, 8, 60, 80)
            nn.ConvTranspose2d(c1, 1, 4, 2, 1))  # (B, 1, 120, 160): logits, no BatchNorm, no ReLU

    def encode(self, x: torch.Tensor) -> torch.Tensor:
        """(B, 1, 120, 160) in [0, 1] -> (B, features) in [-1, 1]."""
        h = self.conv(x)                         # (B, 64, 3, 4)
        return self.fc(h.flatten(1))             # (B, 768) -> (B, 10)

    def logits(self, z: torch.Tensor) -> torch.Tensor:
        """(B, features) -> pre-sigmoid reconstruction (B, 1, 120, 160)."""
        h = self.unfc(z)                         # (B, 768)
        h = h.view(-1, *self.map_shape)          # (B, 64, 3, 4)
        return self.deconv(h.contiguous(memory_format=torch.channels_last))

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        """Reconstruction x̂ = sigmoid(decoder(encoder(x))), (B, 1, 120, 160) in [0, 1]."""
        return torch.sigmoid(self.logits(self.encode(x)))

    def fused_encoder(self) -> nn.Sequential:
        """The encoder for inference, each BatchNorm folded into the conv before it: same output, ~2x faster."""
        layers, out = list(self.conv), []
        for i, layer in enumerate(layers):
            nxt = layers[i + 1] if i + 1 < len(layers) else None
            if isinstance(layer, nn.Conv2d) and isinstance(nxt, nn.BatchNorm2d):
                out.append(fuse_conv_bn_eval(layer, nxt))  # conv, then its BN: w' = w·γ/σ, b' = β − μ·γ/σ
            elif not isinstance(layer, nn.BatchNorm2d):
                out.append(layer)
        return nn.Sequential(*out, nn.Flatten(), *self.fc).eval()  # (B, 1, 120, 160) -> (B, 10)


def as_input(images: np.ndarray | torch.Tensor, device: torch.device | str | None = None) -> torch.Tensor:
    """A batch of images in the module's convention -> float (B, 3, 120, 160) in [0, 1] on ``device``."""
    x = torch.as_tensor(images)
    shape = tuple(x.shape)
    if x.dim() != 4 or shape[1:] not in ((HEIGHT, WIDTH, 3), (3, HEIGHT, WIDTH)):
        hint = " (one image? add a batch axis: images[None])" if x.dim() == 3 else ""
        raise ValueError(f"expected a batch of images shaped (B, {HEIGHT}, {WIDTH}, 3) or "
                         f"(B, 3, {HEIGHT}, {WIDTH}); got {shape}{hint}")
    if x.dtype != torch.uint8 and not x.is_floating_point():
        raise ValueError(f"images must be uint8 (0..255) or float (0..1); got {x.dtype}")
    x = x.to(device) if device is not None else x  # move uint8 (4x less to copy), then convert
    if shape[-1] == 3:
        x = x.permute(0, 3, 1, 2)                # (B, 120, 160, 3) -> (B, 3, 120, 160)
    if x.dtype == torch.uint8:
        return x.float() / 255.0
    if len(x) and (x.min() < 0 or x.max() > 1):
        raise ValueError("float images must lie in [0, 1] (for 0..255 values pass uint8, or divide by 255)")
    return x.float()


class ChannelSeparatedCAE(nn.Module):
    """Three :class:`ChannelAutoencoder` s, one per colour: RGB frames <-> 30 features [R10, G10, B10].

    ``autoencoder(config)`` builds each colour's (default the book's; the course's lab on the channel widths
    hands in a student's, a module with ``encode``, ``logits`` and ``forward`` as ChannelAutoencoder's)."""

    def __init__(self, config: CAEConfig = CAEConfig(), autoencoder: Callable[[CAEConfig], nn.Module] | None = None):
        super().__init__()
        self.config = config
        self.red, self.green, self.blue = ((autoencoder or ChannelAutoencoder)(config) for _ in COLOURS)
        # Speed: channels-last convolutions train ~15% faster on a CPU (and are harmless on CUDA).
        self.to(memory_format=torch.channels_last)

    @property
    def channels(self) -> tuple[ChannelAutoencoder, ...]:
        return (self.red, self.green, self.blue)

    @property
    def device(self) -> torch.device:
        return next(self.parameters()).device

    def _split(self, images) -> list[torch.Tensor]:
        x = as_input(images, self.device)       # (B, 3, 120, 160)
        # (B, 3, 120, 160) -> 3 x (B, 1, 120, 160), each laid out channels-last (= plain for 1 channel)
        return [x[:, i:i + 1].contiguous(memory_format=torch.channels_last) for i in range(3)]

    def encode(self, images) -> torch.Tensor:
        """Images (B, 120, 160, 3) or (B, 3, 120, 160) -> features (B, 30) = [R10, G10, B10]."""
        return torch.cat([ae.encode(x) for ae, x in zip(self.channels, self._split(images))], dim=1)

    def forward(self, images) -> torch.Tensor:
        """Reconstructions (B, 3, 120, 160) in [0, 1]."""
        return torch.cat([ae(x) for ae, x in zip(self.channels, self._split(images))], dim=1)

    def loss(self, images) -> tuple[torch.Tensor, torch.Tensor]:
        """Mean BCE over the three channels, and each channel's BCE (3,)."""
        # BCE(x, sigmoid(l)) computed from the logits l: the same value, numerically safer.
        bce = torch.stack([nn.functional.binary_cross_entropy_with_logits(ae.logits(ae.encode(x)), x)
                           for ae, x in zip(self.channels, self._split(images))])
        # Parameters of the three autoencoders are disjoint: one optimiser on the mean
        # trains them as three separate CAEs on the same batches (authors: three runs).
        return bce.mean(), bce


def _fingerprint(images: np.ndarray) -> dict:
    """Shape and a checksum of up to 64 evenly spaced images: tells training sets apart cheaply."""
    pick = np.linspace(0, len(images) - 1, min(len(images), 64)).astype(int)
    return {"shape": list(images.shape), "crc32": zlib.crc32(np.ascontiguousarray(images[pick]).tobytes())}


def train_cae(images: np.ndarray, config: CAEConfig, device: torch.device | str | None = None,
              progress: bool = True, out_path: str | Path | None = None,
              autoencoder: Callable[[CAEConfig], nn.Module] | None = None) -> tuple[ChannelSeparatedCAE, list[dict]]:
    """Train a :class:`ChannelSeparatedCAE` on ``images`` (N, 120, 160, 3) uint8.

    Batches are drawn without replacement from a seeded shuffle (a new one each
    pass over the data), and on the CPU it runs on a fixed number of torch threads
    (:func:`~pgae_lite.util.storage.training_threads`), so a seed gives the same weights bit for
    bit on the same kind of device, whatever the caller's thread count. History: one record per
    iteration, ``{"iteration", "loss", "red", "green", "blue"}`` (BCE).

    With ``out_path`` the finished model is written there atomically; if that
    file already holds a model trained with the same config on the same images
    it is loaded instead of training again. Any other file there is refused. ``autoencoder``: each
    colour's, as :class:`ChannelSeparatedCAE` takes it (another than the book's is never saved).
    """
    if autoencoder is not None and out_path is not None:
        raise ValueError("train_cae saves only the book's ChannelAutoencoder: with autoencoder=, out_path=None")
    if not isinstance(config, CAEConfig):
        raise TypeError(f"train_cae wants a CAEConfig, e.g. pgae_lite.config.get_profile().cae; got {config!r}")
    images = np.asarray(images)
    if images.ndim != 4 or images.shape[1:] != (HEIGHT, WIDTH, 3) or images.dtype != np.uint8 or not len(images):
        raise ValueError(f"train_cae wants uint8 images (N, {HEIGHT}, {WIDTH}, 3), N > 0; "
                         f"got {images.dtype} {images.shape}")
    device = torch.device(device) if device else default_device()
    data = _fingerprint(images)
    if out_path is not None and Path(out_path).exists():
        model, ckpt = load_cae(out_path, device)
        if ckpt["config"] != config.to_dict() or ckpt["data"] != data:
            what = "config" if ckpt["config"] != config.to_dict() else "set of images"
            raise CheckpointMismatchError(f"{out_path} holds a CAE trained with a different {what} "
                                          f"({ckpt['config']['name']!r}); use another path, or delete it to retrain")
        return model, ckpt["history"]

    torch.manual_seed(config.seed)
    model = ChannelSeparatedCAE(config, autoencoder).to(device)
    optimiser = torch.optim.Adam(model.parameters(), lr=config.lr)
    rng = np.random.default_rng(config.seed)
    t0 = time.perf_counter()
    model.train()
    # On CUDA, cuDNN may pick convolution kernels that add in a varying order: ask for
    # deterministic ones, so that a seed gives the same weights there too (no effect on the CPU).
    # On the CPU, a fixed number of threads (utils.training_threads): the same weights on any machine.
    deterministic = torch.backends.cudnn.flags(enabled=True, benchmark=False, deterministic=True)
    with deterministic, training_threads(device):
        history = _train_loop(model, optimiser, images, config, rng, progress)
    model.eval()
    if out_path is not None:                 # atomic: a crash never leaves half a file
        save_torch({"model": model.state_dict(), "config": config.to_dict(),
                    "data": data, "history": history,
                    "seconds": time.perf_counter() - t0}, out_path)
    return model, history


def _train_loop(model: ChannelSeparatedCAE, optimiser: torch.optim.Optimizer, images: np.ndarray,
                config: CAEConfig, rng: np.random.Generator, progress: bool) -> list[dict]:
    """``config.iterations`` steps of Adam on batches drawn without replacement; the history."""
    order, pos, history = rng.permutation(len(images)), 0, []
    for it in tqdm(range(config.iterations), desc=f"CAE ({config.name})", disable=not progress):
        if pos + config.batch_size > len(order):  # a new shuffle when a pass is done
            order, pos = rng.permutation(len(images)), 0
        index = np.sort(order[pos:pos + config.batch_size])  # sorted: faster reads (e.g. memory-mapped files)
        pos += config.batch_size
        loss, per_channel = model.loss(images[index])   # uint8 (b, 120, 160, 3)
        optimiser.zero_grad(set_to_none=True)
        loss.backward()
        optimiser.step()
        r, g, b = per_channel.tolist()
        history.append({"iteration": it + 1, "loss": (r + g + b) / 3, "red": r, "green": g, "blue": b})
    return history


def load_cae(path: str | Path, device: torch.device | str | None = None) -> tuple[ChannelSeparatedCAE, dict]:
    """A trained CAE (in eval mode) and its checkpoint's other contents, through the checks of every saved file
    (:func:`~pgae_lite.util.storage.load_torch`: finite weights; :func:`~pgae_lite.util.storage.config_from`:
    known settings; :func:`~pgae_lite.util.storage.load_state`: the expected tensors), each failure one sentence."""
    from pgae_lite.util.storage import config_from, load_state

    ckpt = load_torch(path, ("model", "config", "data", "history"), "CAE checkpoint", finite=("model",))
    config = CAEConfig.from_dict(asdict(config_from(CAEConfig, ckpt["config"], path, "CAE settings")))
    model = load_state(ChannelSeparatedCAE(config), ckpt["model"], path, "CAE")
    return model.to(device or default_device()).eval(), ckpt


@torch.inference_mode()
def extract_features(model: ChannelSeparatedCAE, images: np.ndarray | torch.Tensor, batch: int = 128) -> np.ndarray:
    """Visual features (N, 30) float32 of ``images``, ``batch`` at a time, on the model's device.

    Equal to ``model.encode(images)`` (to float precision), in batches, so the
    whole dataset never has to sit in memory as float.
    """
    was_training = model.training
    model.eval()                                         # BatchNorm: running statistics
    encoders = [ae.fused_encoder() for ae in model.channels]
    out = []
    with torch.backends.cudnn.flags(enabled=True, benchmark=False, deterministic=True):  # as train_cae
        for i in range(0, len(images), batch):
            channels = model._split(images[i:i + batch])   # 3 x (b, 1, 120, 160)
            out.append(torch.cat([enc(x) for enc, x in zip(encoders, channels)], dim=1).float().cpu())  # (b, 30)
    model.train(was_training)
    return torch.cat(out).numpy() if out else np.zeros((0, 3 * model.config.features), np.float32)


@torch.inference_mode()
def reconstruct(model: ChannelSeparatedCAE, images: np.ndarray | torch.Tensor, batch: int = 128) -> np.ndarray:
    """Reconstructions as uint8 (N, 120, 160, 3): for looking at what the 30 features keep."""
    was_training = model.training
    model.eval()
    out = [(model(images[i:i + batch]) * 255).round().byte().permute(0, 2, 3, 1).cpu()  # -> (b, 120, 160, 3)
           for i in range(0, len(images), batch)]
    model.train(was_training)
    return torch.cat(out).numpy() if out else np.zeros((0, HEIGHT, WIDTH, 3), np.uint8)


__all__ = [
    "CAEConfig",
    "ChannelAutoencoder",
    "ChannelSeparatedCAE",
    "as_input",
    "extract_features",
    "load_cae",
    "reconstruct",
    "train_cae",
]
