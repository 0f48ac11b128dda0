"""The authors' data: a reader for the text files of their public repository (oo222bs/PGAE).

Paper, Sec. 4 (Dataset). The authors publish their recordings as one text file
per sample and modality under ``target/{behavior,vision,vision_opp,language}_{train,test}/DATE/``,
with ``actions.txt`` and ``arrangements.txt`` (one line per pattern) beside
``target/``. :func:`load_original` reads them into a :class:`~pgae_lite.data.dataset.PGAEDataset`
and raises :class:`~pgae_lite.data.dataset.DataFormatError` naming what was expected
when anything is missing or malformed: a file and its line for a short or long
row, a value that is not a finite number or lies far outside the data's range,
a language row that is not one-hot (:mod:`pgae_lite.data.checks`), and a
``vocabulary.txt`` whose words differ from :data:`pgae_lite.world.words.VOCABULARY`, a file named
``target*.txt`` whose name holds no pattern number, and a sample whose length is not its speed's
(100 steps slow, 50 fast).
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from pgae_lite.data.checks import (
    JOINT_BOUNDS,
    VISION_LIMIT,
    check_one_hot,
    check_range,
    check_vocabulary,
    read_rows,
    text_of,
)
from pgae_lite.data.dataset import DataFormatError, PGAEDataset
from pgae_lite.world.patterns import MAX_STEPS, Pattern
from pgae_lite.world.words import COLOURS, VOCABULARY

_SUBTREES = ("behavior", "vision", "vision_opp", "language")
#: The world's 144 patterns: line k of actions.txt and arrangements.txt is pattern k - 1.
PATTERNS = [Pattern.from_number(i) for i in range(144)]


def load_original(path: str | Path) -> PGAEDataset:
    """Read the authors' dataset (the folder holding ``target/`` and ``actions.txt``).

    Raises :class:`~pgae_lite.data.dataset.DataFormatError` naming what was expected when the folder,
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
    check_vocabulary(root)

    rows: dict[str, list] = {k: [] for k in (
        "joints", "vision", "vision_opposite", "lengths", "descriptions", "pattern", "is_test",
        "ids", "action", "arrangement")}
    for split in ("train", "test"):
        for date_dir in sorted((target / f"behavior_{split}").iterdir()):
            for f in sorted(date_dir.glob("target*.txt")):
                pattern = _pattern_of(f)
                rel = f"{date_dir.name}/{f.stem}"
                joints = read_rows(f, 5)
                check_range(f, joints, *JOINT_BOUNDS, "joint")
                n = len(joints)
                vision, opposite = (_read_vision(target / f"{v}_{split}" / f"{rel}.txt")
                                    for v in ("vision", "vision_opp"))
                lang_file = target / f"language_{split}" / f"{rel}.txt"
                lang = read_rows(lang_file, len(VOCABULARY))
                check_one_hot(lang_file, lang)
                if len(vision) != n or len(opposite) != n or not 0 < n <= MAX_STEPS:
                    raise DataFormatError(
                        f"{f}: joints, vision and opposite vision must have the same "
                        f"number of steps (<= {MAX_STEPS}); got {n}, {len(vision)}, "
                        f"{len(opposite)}")
                if lang.shape[0] != 40:
                    raise DataFormatError(f"{lang_file}: a language file has 40 "
                                          "one-hot rows (8 x 5), found "
                                          f"{lang.shape[0]}")
                if pattern not in pattern_info:
                    raise DataFormatError(f"{rel}: pattern {pattern} not listed in actions.txt")
                _check_steps(f, n, PATTERNS[pattern])
                words = _descriptions(lang_file, lang, pattern)
                action, arrangement, split_name = pattern_info[pattern]
                if split_name != split:
                    raise DataFormatError(f"{rel}: actions.txt puts pattern {pattern} in {split_name}, "
                                          f"found in {split}")
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


def _pattern_of(path: Path) -> int:
    """The pattern number in a sample's file name, ``target<number>.txt``; a file of another name among the samples
    is refused, naming it, rather than read as a sample or passed over (it may be a renamed one)."""
    found = re.fullmatch(r"target([0-9]{1,6})", path.stem)
    if not found:
        raise DataFormatError(f"{path} is not a sample's file: the authors name each sample target<pattern number>"
                              f".txt (target000017.txt); rename it so, or move it out of {path.parent}")
    return int(found.group(1))


def _check_steps(path: Path, steps: int, pattern: Pattern) -> None:
    """A sample must last its speed's steps: the authors record every slow action in 100 steps and every fast
    one in 50 (Pattern.steps; all 864 of their samples do), so another count is a damaged or foreign file."""
    if steps != pattern.steps:
        raise DataFormatError(f"{path}: pattern {pattern.number} is {pattern.code}, which the authors record in "
                              f"{pattern.steps} steps (slow actions {MAX_STEPS}, fast ones {MAX_STEPS // 2}); "
                              f"found {steps}")


def _read_vision(path: Path) -> np.ndarray:
    vision = read_rows(path, 30)
    check_range(path, vision, -VISION_LIMIT, VISION_LIMIT, "visual feature")
    return vision


def _descriptions(path: Path, lang: np.ndarray, pattern: int) -> np.ndarray:
    """The 8 descriptions (8, 3) in a language file's rows, checked with its pattern."""
    tokens = lang.argmax(1).reshape(8, 5)        # (8 alternatives, <BOS> w w w <EOS>)
    expected = Pattern.from_number(pattern).descriptions()                  # (8, 3)
    wrong = (tokens[:, [0, 4]] != 0).any(1) | (tokens[:, 1:4] != expected).any(1)
    if wrong.any():
        k = int(np.argmax(wrong))
        said, meant = (" ".join(VOCABULARY[i] for i in words)
                       for words in (tokens[k], [0, *expected[k], 0]))
        raise DataFormatError(f"{path}, rows {5 * k + 1}-{5 * k + 5}: description "
                              f"{k + 1} reads {said!r}, expected {meant!r} for pattern "
                              f"{pattern}")
    return tokens[:, 1:4]


def _entries(path: Path) -> list[tuple[int, list[str]]]:
    """(line number, words) of each non-blank line of one of the authors' pattern files."""
    if not path.is_file():
        raise DataFormatError(f"missing {path} (one line per pattern, from the authors' repository)")
    return [(n, line.split()) for n, line in enumerate(text_of(path).splitlines(), 1) if line.strip()]


def _read_patterns(root: Path) -> dict[int, tuple[str, str, str]]:
    """Pattern number -> (action label, arrangement, split) from ``actions.txt`` and ``arrangements.txt``:
    line k of each must be the world's pattern k - 1 (:class:`~pgae_lite.world.patterns.Pattern`)."""
    actions_file, arrangements_file = root / "actions.txt", root / "arrangements.txt"
    actions, arrangements = _entries(actions_file), _entries(arrangements_file)
    labels = [f"{a}-{side}-{speed}" for a in ("PUSH", "PULL", "SLIDE") for side in "LR" for speed in ("SLOW", "FAST")]
    for line, words in actions:
        label, split = (words + ["", ""])[:2]
        if len(words) != 2 or label not in labels or split not in ("train", "test"):
            raise DataFormatError(f"{actions_file}, line {line}: {' '.join(words)!r:.60} is not an action of the "
                                  f"world and a split; each line must be 'ACTION-CUBE-SPEED train|test' with the "
                                  f"actions {', '.join(labels)}")
    for line, words in arrangements:
        if len(words) != 1 or words[0].count("+") != 1 or not all(c in COLOURS for c in words[0].split("+")):
            raise DataFormatError(f"{arrangements_file}, line {line}: {' '.join(words)!r:.40} is not two "
                                  f"colours of the world joined by '+'; the colours are {', '.join(COLOURS)}")
    if len(actions) != len(arrangements) or len(actions) > len(PATTERNS):
        raise DataFormatError(f"{actions_file} and {arrangements_file} must have one line per pattern, at most "
                              f"{len(PATTERNS)}; found {len(actions)} and {len(arrangements)}")
    for number, ((line, (label, split)), (_, (arrangement,))) in enumerate(zip(actions, arrangements)):
        p = PATTERNS[number]
        world = (p.code, "test" if p.is_test else "train", f"{p.left}+{p.right}")
        if (label, split, arrangement) != world:
            raise DataFormatError(f"{actions_file}, line {line}: pattern {number} is {' '.join(world)!r} in the "
                                  f"world (pgae_lite.world.patterns); the files say {label} {split} {arrangement}")
    return {i: (a[1][0], arr[1][0], a[1][1]) for i, (a, arr) in enumerate(zip(actions, arrangements))}


__all__ = ["load_original"]
