"""Datasets: one type for the authors' recordings and for our simulator's.

Paper, Sec. 4 (Dataset). A sample is one recording of one of 144 patterns
(12 cube arrangements x 12 actions): per time step 5 joint angles and 30
visual features (10 per colour channel), for NICO's own view and for the
opposite agent's; slow actions last 100 steps, fast ones 50, padded to 100
with a mask. Each sample carries the 8 equivalent descriptions of its action.

:func:`load_original` reads the authors' ``target/`` tree;
:class:`Normaliser` maps every modality to [-1, 1] with statistics from the
training split only.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterable

import numpy as np
import torch

from .language import VOCABULARY, WORD_INDEX, equivalent_descriptions
from .utils import atomic_write

MAX_STEPS = 100
JOINT_DIM = 5
VISION_DIM = 30


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
        """``"train"`` or ``"test"`` samples."""
        if name not in ("train", "test"):
            raise ValueError(f"unknown split {name!r}; the splits are: train, test")
        return self.subset(self.is_test if name == "test" else ~self.is_test)

    def joint_range(self) -> float:
        """Observed range (max - min) of joint values over valid steps: nRMSE's denominator."""
        valid = self.joints[self.mask]
        return float(valid.max() - valid.min())

    def save(self, path: str | Path) -> None:
        """Write every array to one ``.npz`` file, atomically (a temporary file, then a rename)."""
        path = Path(path)
        arrays = {k: getattr(self, k) for k in _ARRAYS}
        with atomic_write(path) as f:
            np.savez_compressed(f, source=np.array(self.source), **arrays)

    @classmethod
    def load(cls, path: str | Path) -> "PGAEDataset":
        """Read a file written by :meth:`save`; :class:`DataFormatError` if it is damaged."""
        try:
            with np.load(path, allow_pickle=False) as f:
                arrays = {k: f[k] for k in _ARRAYS}
                source = str(f["source"])
        except Exception as e:  # zip, zlib, missing keys: all mean a damaged or foreign file
            raise DataFormatError(f"{path}: not a readable PGAE dataset file ({type(e).__name__}: {e})") from None
        n = len(arrays["lengths"])
        if any(len(a) != n for a in arrays.values()) or arrays["joints"].shape[1:] != (MAX_STEPS, JOINT_DIM):
            raise DataFormatError(f"{path}: arrays of inconsistent shapes")
        return cls(**arrays, source=source)


#: How visual features can be scaled to [-1, 1] (see :meth:`Normaliser.fit`).
VISION_SCALINGS = ("global", "whiten")
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
    the training split, so that one picture means the same numbers in both
    views), then scaled.
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
        features) or ``"whiten"`` (whitened first: every direction of the 30-d feature
        space gets about the same variance, then one min and max).
        """
        check_vision_scaling(vision_scaling)
        m = data.mask
        white = None
        if vision_scaling == "whiten":
            mean, W = whitening(data.vision[m])                                   # NICO's view, (30,), (30, 30)
            white = (tuple(map(float, mean)), tuple(tuple(map(float, row)) for row in W))

        def lo_hi(x: np.ndarray) -> tuple[float, float]:
            return float(x[m].min()), float(x[m].max())
        return cls(lo_hi(data.joints), lo_hi(_whiten(data.vision, white)),
                   lo_hi(_whiten(data.vision_opposite, white)), white)

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


# --------------------------------------------------------------------------- the 144 patterns
#: The 12 cube arrangements (left+right), in the order of the authors' data.
ARRANGEMENTS: tuple[tuple[str, str], ...] = (
    ("red", "blue"), ("green", "red"), ("blue", "green"), ("blue", "red"), ("red", "green"),
    ("green", "blue"), ("yellow", "violet"), ("cyan", "yellow"), ("violet", "cyan"),
    ("violet", "yellow"), ("yellow", "cyan"), ("cyan", "violet"))
#: Action order within an arrangement: (action, cube side).
ACTION_SIDES: tuple[tuple[str, str], ...] = (
    ("push", "L"), ("pull", "L"), ("slide", "L"), ("push", "R"), ("pull", "R"), ("slide", "R"))
#: The 36 test patterns of the paper's split (the authors' actions.txt): every word
#: and action type appears in test, but not these combinations of description,
#: action and arrangement.
TEST_PATTERNS: frozenset[int] = frozenset((
    2, 6, 9, 14, 17, 25, 31, 33, 34, 38, 42, 45, 50, 53, 61, 67, 69, 70, 74, 76, 77, 78, 79, 80,
    81, 84, 94, 110, 112, 113, 114, 115, 116, 117, 120, 130))


@dataclass(frozen=True)
class Pattern:
    """One of the 144 patterns: pattern = 72·speed + 6·arrangement + action."""

    number: int
    action: str        # push | pull | slide
    side: str          # L | R: which cube, from NICO's point of view
    speed: str         # slowly | fast
    left: str          # colour of the left cube
    right: str         # colour of the right cube

    @classmethod
    def from_number(cls, number: int) -> "Pattern":
        if not 0 <= number < 144:
            raise ValueError(f"pattern number {number} out of range; patterns are 0-143")
        speed, rest = divmod(number, 72)
        arrangement, action = divmod(rest, 6)
        act, side = ACTION_SIDES[action]
        left, right = ARRANGEMENTS[arrangement]
        return cls(number, act, side, ("slowly", "fast")[speed], left, right)

    @property
    def colour(self) -> str:
        """Colour of the manipulated cube."""
        return self.left if self.side == "L" else self.right

    @property
    def is_test(self) -> bool:
        return self.number in TEST_PATTERNS

    @property
    def steps(self) -> int:
        """Length of a recording: 100 steps slowly, 50 fast."""
        return MAX_STEPS if self.speed == "slowly" else MAX_STEPS // 2

    @property
    def code(self) -> str:
        """The authors' label, e.g. ``PUSH-L-SLOW``."""
        return f"{self.action.upper()}-{self.side}-{'SLOW' if self.speed == 'slowly' else 'FAST'}"

    def descriptions(self) -> np.ndarray:
        """Word indices of the 8 equivalent descriptions, (8, 3)."""
        alts = equivalent_descriptions(self.action, self.colour, self.speed)
        return np.array([[WORD_INDEX[w] for w in alt] for alt in alts])


# --------------------------------------------------------------------------- authors' data
class DataFormatError(ValueError):
    """The authors' data folder is missing or not in the expected format."""


_SUBTREES = ("behavior", "vision", "vision_opp", "language")


def _read_matrix(path: Path, width: int) -> np.ndarray:
    if not path.is_file():
        raise DataFormatError(f"missing file {path}: every sample needs the same file name in all sub-folders")
    try:
        values = np.array(path.read_text().split(), dtype=np.float32)
    except ValueError as e:
        raise DataFormatError(f"{path}: expected rows of {width} numbers ({e})") from None
    if values.size == 0 or values.size % width:
        raise DataFormatError(f"{path}: expected rows of {width} numbers, found {values.size} numbers")
    return values.reshape(-1, width)


def load_original(path: str | Path) -> PGAEDataset:
    """Read the authors' dataset (the folder holding ``target/`` and ``actions.txt``).

    Raises :class:`DataFormatError` naming what was expected when the folder,
    a sub-tree or a file is missing or malformed.
    """
    root = Path(path).expanduser()
    if (root / "target").is_dir():
        target = root / "target"
    elif root.name == "target" and root.is_dir():
        target, root = root, root.parent
    else:
        raise DataFormatError(
            f"{root} is not the authors' PGAE data folder: expected a folder containing 'target/' "
            f"with sub-folders {', '.join(s + '_train' for s in _SUBTREES)} (and *_test), and "
            "'actions.txt' / 'arrangements.txt' beside it (public repository oo222bs/PGAE)")
    for sub in _SUBTREES:
        for split in ("train", "test"):
            if not (target / f"{sub}_{split}").is_dir():
                raise DataFormatError(f"missing folder {target / f'{sub}_{split}'}")
    pattern_info = _read_patterns(root)

    rows: dict[str, list] = {k: [] for k in (
        "joints", "vision", "vision_opposite", "lengths", "descriptions", "pattern", "is_test",
        "ids", "action", "arrangement")}
    for split in ("train", "test"):
        for date_dir in sorted((target / f"behavior_{split}").iterdir()):
            for f in sorted(date_dir.glob("target*.txt")):
                rel = f"{date_dir.name}/{f.stem}"
                joints = _read_matrix(f, 5)
                n = len(joints)
                vision = _read_matrix(target / f"vision_{split}" / f"{rel}.txt", 30)
                opposite = _read_matrix(target / f"vision_opp_{split}" / f"{rel}.txt", 30)
                lang = _read_matrix(target / f"language_{split}" / f"{rel}.txt", len(VOCABULARY))
                if len(vision) != n or len(opposite) != n or not 0 < n <= MAX_STEPS:
                    raise DataFormatError(
                        f"{rel}: joints, vision and opposite vision must have the same number of steps "
                        f"(<= {MAX_STEPS}); got {n}, {len(vision)}, {len(opposite)}")
                if lang.shape[0] != 40:
                    raise DataFormatError(f"{rel}: language file must have 40 one-hot rows (8 x 5), got {lang.shape[0]}")
                words = lang.argmax(1).reshape(8, 5)[:, 1:4]  # (8 alternatives, 3 words)
                pattern = int(f.stem.replace("target", ""))
                if pattern not in pattern_info:
                    raise DataFormatError(f"{rel}: pattern {pattern} not listed in actions.txt")
                action, arrangement, split_name = pattern_info[pattern]
                if split_name != split:
                    raise DataFormatError(f"{rel}: actions.txt puts pattern {pattern} in {split_name}, found in {split}")
                pad = ((0, MAX_STEPS - n), (0, 0))
                rows["joints"].append(np.pad(joints, pad))
                rows["vision"].append(np.pad(vision, pad))
                rows["vision_opposite"].append(np.pad(opposite, pad))
                rows["lengths"].append(n)
                rows["descriptions"].append(words)
                rows["pattern"].append(pattern)
                rows["is_test"].append(split == "test")
                rows["ids"].append(rel)
                rows["action"].append(action)
                rows["arrangement"].append(arrangement)
    if not rows["ids"]:
        raise DataFormatError(f"no samples found under {target}/behavior_train/DATE/target*.txt")
    order = np.argsort(rows["ids"], kind="stable")  # by date, then pattern: a fixed order
    arrays = {k: np.asarray(v)[order] for k, v in rows.items()}
    return PGAEDataset(**arrays, source=f"original:{root}")


def _read_patterns(root: Path) -> dict[int, tuple[str, str, str]]:
    actions_file, arrangements_file = root / "actions.txt", root / "arrangements.txt"
    for f in (actions_file, arrangements_file):
        if not f.is_file():
            raise DataFormatError(f"missing {f} (one line per pattern, from the authors' repository)")
    actions = [line.split() for line in actions_file.read_text().splitlines() if line.strip()]
    arrangements = [line.strip() for line in arrangements_file.read_text().splitlines() if line.strip()]
    if len(actions) != len(arrangements) or any(len(a) != 2 for a in actions):
        raise DataFormatError(f"{actions_file} must have 'ACTION-CUBE-SPEED train|test' per line, "
                              f"as many lines as {arrangements_file}")
    return {i: (a[0], arr, a[1]) for i, (a, arr) in enumerate(zip(actions, arrangements))}


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


__all__ = ["PGAEDataset", "Normaliser", "DataFormatError", "load_original", "from_recordings", "description_text",
           "MAX_STEPS", "JOINT_DIM", "VISION_DIM", "Pattern", "ARRANGEMENTS", "TEST_PATTERNS"]
