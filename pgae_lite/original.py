"""The authors' data: a reader for the text files of their public repository (oo222bs/PGAE).

Paper, Sec. 4 (Dataset). The authors publish their recordings as one text file
per sample and modality under ``target/{behavior,vision,vision_opp,language}_{train,test}/DATE/``,
with ``actions.txt`` and ``arrangements.txt`` (one line per pattern) beside
``target/``. :func:`load_original` reads them into a :class:`~pgae_lite.data.PGAEDataset`
and raises :class:`~pgae_lite.data.DataFormatError` naming what was expected
when anything is missing or malformed.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .data import DataFormatError, PGAEDataset
from .language import VOCABULARY
from .patterns import MAX_STEPS

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

    Raises :class:`~pgae_lite.data.DataFormatError` naming what was expected when the folder,
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


__all__ = ["load_original"]
