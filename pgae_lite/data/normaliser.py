"""Normalising a dataset for the model: every modality to [-1, 1], the visual features whitened (paper Sec. 4).

Paper, Sec. 4 and the authors' code: one global minimum and maximum per modality maps joints and
visual features to [-1, 1]. Deviation from paper: the statistics come from the training split
only, and the book's recipe whitens the visual features of both views first (``vision_scaling``;
experiments/HISTORY.md, "whitening"). :func:`spread_of` measures what a scaling does to the other
agent's view (chapter 06): how widely it lets that view vary beside NICO's own.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from pgae_lite.data.dataset import DataFormatError, PGAEDataset

VISION_SCALINGS = ("global", "whiten", "whiten-per-view")
#: Whitening adds this share of the largest eigenvalue to every eigenvalue before inverting, so
#: that directions with almost no variance are not blown up.
WHITENING_EPS = 0.01


def whitening(x: np.ndarray, eps: float = WHITENING_EPS) -> tuple[np.ndarray, np.ndarray]:
    """ZCA whitening of features ``x`` (N, F): the mean (F,) and a matrix W (F, F) such that
    (x - mean) W has (nearly) the identity as covariance and stays closest to x."""
    x = x.astype(np.float64)
    mean = x.mean(0)
    lam, U = np.linalg.eigh(np.cov(x - mean, rowvar=False))             # C = U diag(λ) Uᵀ
    return mean, U @ np.diag(1 / np.sqrt(lam + eps * lam.max())) @ U.T  # W = U diag(1/√(λ+ε)) Uᵀ


def check_vision_scaling(name: str) -> None:
    """Raise a ValueError naming the allowed scalings unless ``name`` is one of them."""
    if name not in VISION_SCALINGS:
        raise ValueError(f"unknown vision_scaling {name!r}; choose one of: {', '.join(VISION_SCALINGS)}")


def _whiten(x: np.ndarray, white: tuple | None) -> np.ndarray:
    """Visual features ``x`` (..., 30) whitened with ``white = (mean, W)``; unchanged if None."""
    if white is None:
        return x
    mean, W = (np.asarray(a) for a in white)
    return ((x - mean) @ W).astype(np.float32)                              # z = (x - mean) W


@dataclass
class Normaliser:
    """Min/max scaling of each modality to [-1, 1] (one global min and max per modality).

    Deviation from paper: the authors take min/max over train and test
    together; we use the training split only, so the test set stays unseen.
    With ``vision_scaling="whiten"`` the visual features of both views are first
    whitened with one transform (:func:`whitening`, fitted on NICO's own view of
    the training split), then scaled with the min and max of NICO's own view:
    one picture means the same numbers in both views.
    """

    joints: tuple[float, float]
    vision: tuple[float, float]
    vision_opposite: tuple[float, float]
    #: with whitening: (mean, W) as nested tuples, shared by both views
    whitening: tuple | None = None

    @classmethod
    def fit(cls, data: PGAEDataset, vision_scaling: str = "global") -> "Normaliser":
        """Statistics from the valid steps of ``data`` (pass the training split).

        ``vision_scaling``: ``"global"`` (the authors': one min and max over all visual
        features, each view its own) or ``"whiten"`` (whitened first: every direction of the
        30-d feature space gets about the same variance, then NICO's view's min and max for
        both views); ``"whiten-per-view"`` whitens too but gives each view its own min and
        max, as the recipe did before the one-scale fix (chapter 06's ablation).
        """
        check_vision_scaling(vision_scaling)
        data.check_finite()
        m = data.mask
        white = None
        if vision_scaling.startswith("whiten"):
            mean, W = whitening(data.vision[m])                                   # NICO's view, (30,), (30, 30)
            white = (tuple(map(float, mean)), tuple(tuple(map(float, row)) for row in W))

        def lo_hi(name: str, x: np.ndarray) -> tuple[float, float]:
            lo, hi = float(x[m].min()), float(x[m].max())
            if not lo < hi:
                raise DataFormatError(f"{data.source or 'dataset'}: {name} are "
                                      f"constant ({lo:g}) in the training samples: "
                                      "nothing to scale")
            return lo, hi
        vision = lo_hi("visual features", _whiten(data.vision, white))
        # Whitened, the opposite view takes NICO's view's min and max too. With a min and max of its
        # own, a few directions in which only that view varies set its scale and squeeze the opposite
        # agent's motion into part of the range ("whiten-per-view": chapter 06 measures what it costs).
        one_scale = vision_scaling == "whiten"
        opposite = vision if one_scale else lo_hi("opposite views", _whiten(data.vision_opposite, white))
        return cls(lo_hi("joints", data.joints), vision, opposite, white)

    def _vision(self, x: np.ndarray, key: str) -> np.ndarray:
        if self.whitening is None:
            return self._scale(x, getattr(self, key))
        lo, hi = (np.float64(v) for v in getattr(self, key))                # scaled in float64
        return self._scale(_whiten(x, self.whitening), (lo, hi))

    @staticmethod
    def _scale(x: np.ndarray, lo_hi: tuple[float, float]) -> np.ndarray:
        lo, hi = lo_hi
        return (2.0 * (x - lo) / (hi - lo) - 1.0).astype(np.float32)  # x' = 2 (x - min) / (max - min) - 1

    def joints_to_model(self, x: np.ndarray) -> np.ndarray:
        """Joints in the data's own units -> the model's [-1, 1]."""
        return self._scale(x, self.joints)

    def vision_to_model(self, x: np.ndarray, opposite: bool = False) -> np.ndarray:
        """Visual features (NICO's view, or the opposite agent's) -> the model's [-1, 1]."""
        return self._vision(x, "vision_opposite" if opposite else "vision")

    def joints_to_data(self, x: np.ndarray | torch.Tensor) -> np.ndarray | torch.Tensor:
        """Inverse of the joint scaling: [-1, 1] -> the data's own units."""
        lo, hi = self.joints
        return (x + 1.0) * (hi - lo) / 2.0 + lo

    def tensors(self, data: PGAEDataset, device: torch.device | str = "cpu") -> dict[str, torch.Tensor]:
        """Normalised tensors of a dataset on ``device``, padded steps set to 0."""
        m = data.mask[..., None]
        return {
            "joints": torch.from_numpy(self._scale(data.joints, self.joints) * m).to(device),
            "vision": torch.from_numpy(self._vision(data.vision, "vision") * m).to(device),
            "vision_opposite": torch.from_numpy(self._vision(data.vision_opposite, "vision_opposite") * m).to(device),
            "lengths": torch.from_numpy(data.lengths.astype(np.int64)).to(device),
            "descriptions": torch.from_numpy(data.descriptions.astype(np.int64)).to(device),
        }

    def state_dict(self) -> dict:
        state = {"joints": list(self.joints), "vision": list(self.vision),
                 "vision_opposite": list(self.vision_opposite)}
        if self.whitening is not None:
            mean, W = self.whitening
            state["whitening"] = [list(mean), [list(row) for row in W]]
        return state

    @classmethod
    def from_state_dict(cls, state: dict) -> "Normaliser":
        white = state.get("whitening")
        if white is not None:
            mean, W = white
            white = (tuple(map(float, mean)), tuple(tuple(map(float, row)) for row in W))
        return cls(*(tuple(float(x) for x in state[k]) for k in ("joints", "vision", "vision_opposite")), white)


def spread_of(data: PGAEDataset, scaling: str) -> float:
    """The opposite view's std over NICO's view's after ``scaling``, feature by feature, averaged (chapter 06).

    Fitted and measured on the valid steps of ``data``'s training split: 1 means the other agent's
    view varies as widely as NICO's own in the model's [-1, 1]; below 1, it is squeezed.
    """
    train_set = data.split("train")
    t = Normaliser.fit(train_set, scaling).tensors(train_set)
    valid = torch.from_numpy(train_set.mask)
    mine, theirs = t["vision"][valid].std(0), t["vision_opposite"][valid].std(0)      # (30,) each
    return float((theirs / mine).mean())


__all__ = ["Normaliser", "VISION_SCALINGS", "WHITENING_EPS", "check_vision_scaling", "spread_of", "whitening"]
