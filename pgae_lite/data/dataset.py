"""Datasets: one type for the authors' recordings and for our simulator's, and their normalisation.

Paper, Sec. 4 (Dataset). A sample is one recording of one of 144 patterns
(12 cube arrangements x 12 actions, :mod:`pgae_lite.world.patterns`): per time step
5 joint angles and 30 visual features (10 per colour channel), for NICO's own
view and for the opposite agent's; slow actions last 100 steps, fast ones 50,
padded to 100 with a mask. Each sample carries the 8 equivalent descriptions
of its action.

:func:`pgae_lite.data.original.load_original` reads the authors' ``target/`` tree;
:class:`~pgae_lite.data.normaliser.Normaliser` maps every modality to [-1, 1] with statistics
from the training split only.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterable

import numpy as np

from pgae_lite.util.errors import PGAELiteError
from pgae_lite.util.storage import array_digest, atomic_write
from pgae_lite.world.patterns import MAX_STEPS, Pattern
from pgae_lite.world.words import VOCABULARY

JOINT_DIM = 5
VISION_DIM = 30


class DataFormatError(PGAELiteError, ValueError):
    """The authors' data folder (:mod:`pgae_lite.data.original`) or a dataset file is missing or malformed."""


_ARRAYS = ("joints", "vision", "vision_opposite", "lengths", "descriptions", "pattern",
           "is_test", "ids", "action", "arrangement")


@dataclass
class PGAEDataset:
    """All samples of a dataset, padded to ``MAX_STEPS`` (values past a length are 0).

    Arrays (N = number of samples, T = 100 steps):
    ``joints`` (N, T, 5) and ``vision`` / ``vision_opposite`` (N, T, 30) in the
    data's own units; ``lengths`` (N,); ``descriptions`` (N, 8, 3) word indices
    of the 8 equivalent descriptions; ``pattern`` (N,) pattern number 0-143;
    ``is_test`` (N,); ``ids`` sample names; ``action`` (e.g. ``PUSH-L-SLOW``)
    and ``arrangement`` (e.g. ``red+blue``) per sample.
    """

    joints: np.ndarray
    vision: np.ndarray
    vision_opposite: np.ndarray
    lengths: np.ndarray
    descriptions: np.ndarray
    pattern: np.ndarray
    is_test: np.ndarray
    ids: np.ndarray
    action: np.ndarray
    arrangement: np.ndarray
    source: str = ""
    extras: dict = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.lengths)

    @property
    def mask(self) -> np.ndarray:
        """(N, T) bool, True on valid steps."""
        return np.arange(self.joints.shape[1])[None, :] < self.lengths[:, None]

    def subset(self, index: np.ndarray) -> "PGAEDataset":
        """The samples at ``index`` (a bool mask or integer indices)."""
        arrays = {k: getattr(self, k)[index] for k in _ARRAYS}
        return PGAEDataset(**arrays, source=self.source, extras=self.extras)

    def split(self, name: str) -> "PGAEDataset":
        """``"train"`` or ``"test"`` samples; :class:`DataFormatError` if none."""
        if name not in ("train", "test"):
            raise ValueError(f"unknown split {name!r}; the splits are: train, test")
        part = self.subset(self.is_test if name == "test" else ~self.is_test)
        if not len(part):
            other = "training" if name == "test" else "test"
            raise DataFormatError(
                f"{self.source or 'the dataset'} has no {name} samples (all "
                f"{len(self)} are {other} samples); training needs training samples "
                "and evaluation test samples")
        return part

    def check_finite(self) -> None:
        """:class:`DataFormatError` naming the sample if a valid step is not finite."""
        for name in ("joints", "vision", "vision_opposite"):
            bad = ~np.isfinite(getattr(self, name)).all(-1) & self.mask     # (N, T)
            if bad.any():
                sample, step = np.argwhere(bad)[0]
                raise DataFormatError(
                    f"{self.source or 'dataset'}: sample {self.ids[sample]}, step "
                    f"{step}: {name} holds NaN or infinity; every value must be a "
                    "finite number")

    def joint_range(self) -> float:
        """Observed range (max - min) of joint values over valid steps: nRMSE's denominator."""
        valid = self.joints[self.mask]
        return float(valid.max() - valid.min())

    def save(self, path: str | Path, fingerprint: str = "") -> None:
        """Write every array to one ``.npz`` file, atomically (temporary file, rename).

        ``fingerprint`` (e.g. a digest of the configs that made the data) is stored
        with a digest of the arrays; :meth:`load` can ask for both.
        """
        path = Path(path)
        arrays = {k: getattr(self, k) for k in _ARRAYS}
        digest = array_digest({**arrays, "fingerprint": np.array(fingerprint)})
        with atomic_write(path) as f:
            np.savez_compressed(f, source=np.array(self.source),
                                digest=np.array(digest),
                                fingerprint=np.array(fingerprint), **arrays)

    @classmethod
    def load(cls, path: str | Path, fingerprint: str | None = None) -> "PGAEDataset":
        """A file written by :meth:`save`; :class:`DataFormatError` if it is damaged.

        With ``fingerprint``, the file must have been saved with that fingerprint
        and its arrays must match the digest saved with them (a cache's check).
        """
        try:
            with np.load(path, allow_pickle=False) as f:
                arrays = {k: f[k] for k in _ARRAYS}
                source = str(f["source"])
                saved = {k: str(f[k]) if k in f else None
                         for k in ("fingerprint", "digest")}
        except Exception as e:  # zip, zlib, missing keys: all mean a damaged or foreign file
            raise DataFormatError(f"{path}: not a readable PGAE dataset file ({type(e).__name__}: {e})") from None
        if fingerprint is not None and saved["fingerprint"] != fingerprint:
            found = (f"fingerprint {saved['fingerprint']!r}" if saved["fingerprint"]
                     else "saved without a fingerprint")
            raise DataFormatError(f"{path}: made from other data or configs ({found}, "
                                  f"expected {fingerprint!r})")
        stamp = np.array(saved["fingerprint"] or "")
        content = array_digest({**arrays, "fingerprint": stamp})
        checked = fingerprint is not None or saved["digest"] is not None
        if checked and saved["digest"] != content:
            raise DataFormatError(f"{path}: its arrays do not match the digest saved "
                                  "with them")
        _check_contents(path, arrays)
        data = cls(**arrays, source=source)
        data.check_finite()
        return data


def _check_contents(path, arrays: dict[str, np.ndarray]) -> None:
    """:class:`DataFormatError` unless the arrays of a dataset file have the shapes, kinds and ranges
    :class:`PGAEDataset` describes (an integer ``is_test`` would select samples by index, not by flag)."""
    n = arrays["lengths"].shape[0] if arrays["lengths"].ndim else -1
    steps = {"joints": (n, MAX_STEPS, JOINT_DIM), "vision": (n, MAX_STEPS, VISION_DIM),
             "vision_opposite": (n, MAX_STEPS, VISION_DIM), "descriptions": (n, 8, 3)}
    kinds = {"f": "numbers", "iu": "whole numbers", "b": "true or false", "U": "text"}
    for name, kind in (("joints", "f"), ("vision", "f"), ("vision_opposite", "f"), ("lengths", "iu"),
                       ("descriptions", "iu"), ("pattern", "iu"), ("is_test", "b"), ("ids", "U"),
                       ("action", "U"), ("arrangement", "U")):
        a, shape = arrays[name], steps.get(name, (n,))
        if a.shape != shape or a.dtype.kind not in kind:
            raise DataFormatError(f"{path}: {name} must hold {kinds[kind]} of shape {shape}; found {a.dtype} "
                                  f"of shape {a.shape} (a file written by PGAEDataset.save holds them)")
    for name, low, high in (("lengths", 1, MAX_STEPS), ("descriptions", 0, None), ("pattern", 0, None)):
        a = arrays[name]
        if a.size and (a.min() < low or (high is not None and a.max() > high)):
            allowed = f"from {low} to {high}" if high is not None else f"{low} or more"
            raise DataFormatError(f"{path}: {name} must be {allowed}; found {a.min()} to {a.max()}")


#: How visual features can be scaled to [-1, 1] (see :meth:`Normaliser.fit`).
def from_recordings(recordings: Iterable[tuple[Pattern, str, np.ndarray, np.ndarray, np.ndarray]],
                    source: str) -> PGAEDataset:
    """A :class:`PGAEDataset` from recordings ``(pattern, id, joints (n, 5), vision (n, 30), opposite (n, 30))``.

    Pads every recording to ``MAX_STEPS`` and derives the descriptions, split,
    action and arrangement from its pattern.
    """
    rows: dict[str, list] = {k: [] for k in _ARRAYS}
    for pattern, sample_id, joints, vision, opposite in recordings:
        pad = ((0, MAX_STEPS - len(joints)), (0, 0))
        rows["joints"].append(np.pad(joints, pad))
        rows["vision"].append(np.pad(vision, pad))
        rows["vision_opposite"].append(np.pad(opposite, pad))
        rows["lengths"].append(len(joints))
        rows["descriptions"].append(pattern.descriptions())
        rows["pattern"].append(pattern.number)
        rows["is_test"].append(pattern.is_test)
        rows["ids"].append(sample_id)
        rows["action"].append(pattern.code)
        rows["arrangement"].append(f"{pattern.left}+{pattern.right}")
    arrays = {k: np.asarray(v) for k, v in rows.items()}
    for k in ("joints", "vision", "vision_opposite"):
        arrays[k] = arrays[k].astype(np.float32)
    return PGAEDataset(**arrays, source=source)


def description_text(indices: np.ndarray) -> str:
    """Word indices of one description -> text."""
    return " ".join(VOCABULARY[int(i)] for i in indices)


__all__ = ["PGAEDataset", "DataFormatError", "from_recordings", "description_text", "JOINT_DIM",
           "VISION_DIM"]
