"""Free-form paraphrases of the test instructions (paper, Sec. 3 on PGAE-BERT and Sec. 5).

The paper says a pretrained language encoder "has the potential to recognise
unseen natural language". To measure it, ``paraphrases.tsv`` holds 108
sentences, three for each of the 36 test instructions, written once and kept
fixed: other words for the action ("shove", "bring closer"), the colour
("crimson", "turquoise"), the speed ("gently", "in a hurry") and filler words
("please", "the ... block"). None of them parses with PGAE's 22-word
vocabulary, so the LSTM language encoder must reject them; PGAE-BERT reads them.
"""
from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

from pgae_lite.world.words import ACTIONS, COLOURS, SPEEDS

PARAPHRASE_FILE = Path(__file__).with_name("paraphrases.tsv")


@dataclass(frozen=True)
class Paraphrase:
    """A free-form instruction and the canonical meaning it stands for."""

    text: str
    action: str   # push | pull | slide
    colour: str   # red | green | blue | yellow | cyan | violet
    speed: str    # slowly | fast

    @property
    def meaning(self) -> tuple[str, str, str]:
        """The canonical description, e.g. ``("push", "red", "slowly")``."""
        return self.action, self.colour, self.speed


def load_paraphrases(path: str | Path | None = None) -> list[Paraphrase]:
    """The paraphrases in the file's order (lines starting with ``#`` are comments).

    ``path``: a paraphrase file; None, the package's own (``PARAPHRASE_FILE``).
    """
    path = PARAPHRASE_FILE if path is None else path
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader((line for line in f if not line.startswith("#")), delimiter="\t"))
    out = []
    for n, row in enumerate(rows, 1):
        p = Paraphrase(row["text"].strip(), row["action"], row["colour"], row["speed"])
        if p.action not in ACTIONS or p.colour not in COLOURS or p.speed not in SPEEDS:
            raise ValueError(f"{path}, entry {n}: meaning {p.meaning} is not action/colour/speed from "
                             f"{ACTIONS} / {COLOURS} / {SPEEDS}")
        out.append(p)
    return out


def paraphrases_for(action: str, colour: str, speed: str) -> list[Paraphrase]:
    """The paraphrases of one canonical instruction."""
    return [p for p in load_paraphrases() if p.meaning == (action, colour, speed)]


__all__ = ["Paraphrase", "load_paraphrases", "paraphrases_for", "PARAPHRASE_FILE"]
