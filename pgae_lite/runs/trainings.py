"""Trainings that are not rows of Table 1, each built here, beside the runs that use them.

A :class:`~pgae_lite.config.Training` is a name (its cache folder's) and what it changes in a
profile's recipe; :func:`pgae_lite.runs.pipeline.trained_pgae` takes these values as it takes
Table 1's trainings by name.

- :data:`NO_PLAN`: the book recipe without its plan head, to show what the head changes
  (chapters 04 and 07; the plan head is ``# Deviation from paper:`` in :mod:`pgae_lite.model.config`).
- :data:`PHRASINGS`: the free-form variant (chapter 05, the playground of chapter 08; not in the
  paper): PGAE-BERT reading the transformer's tokens through an attention pooling
  (:mod:`pgae_lite.bert.attention_pooling`) in place of the mean, with the transformer's top layer
  tuned for free text (:mod:`pgae_lite.bert.tuned_layer`; the fixed inputs keep the frozen one),
  trained on 60 phrasings of every instruction under repeat language only: it says a sentence back
  in the dataset's words and executes those (:mod:`pgae_lite.robot.instructions`, route "said
  back"), so execute reads the descriptions alone. Chosen on validation sentences
  (``experiments/validation_readback.py``; experiments/HISTORY.md), never on the test paraphrases.
- :data:`PHRASINGS_HELD_OUT`: the same with some words never trained on
  (:func:`pgae_lite.bert.phrase_lexicon.held_out_words`): ``benchmarks/free_language.py``'s "unseen" measure.
"""
from __future__ import annotations

from pgae_lite.config import TRAININGS, Training

#: The book recipe without its plan head (chapters 04 and 07).
NO_PLAN = Training("PGAE-no-plan", model={"plan_keyframes": 0})

_FREE_FORM_MODEL = {"language_encoder": "pretrained-attention", "tuned_top_layer": True}
#: The free-form variant (chapters 05 and 08; not in the paper).
PHRASINGS = Training("PGAE-BERT-phrasings", model=_FREE_FORM_MODEL,
                     train={"phrasings": 60, "phrasing_signals": ("repeat language",)})
#: The free-form variant trained without the held-out words (``benchmarks/free_language.py``).
PHRASINGS_HELD_OUT = Training("PGAE-BERT-phrasings-held-out", model=_FREE_FORM_MODEL,
                              train={**PHRASINGS.train, "phrasing_words": "held-out"})

#: Every training of this module, by name.
SIDE_TRAININGS: dict[str, Training] = {t.name: t for t in (NO_PLAN, PHRASINGS, PHRASINGS_HELD_OUT)}



def by_name(name: str) -> Training:
    """Any training by its name, Table 1's or one of this module's: for a command line's arguments."""
    every = {**TRAININGS, **SIDE_TRAININGS}
    if name not in every:
        raise ValueError(f"unknown training {name!r}; the trainings are: {', '.join(every)}")
    return every[name]


__all__ = ["NO_PLAN", "PHRASINGS", "PHRASINGS_HELD_OUT", "SIDE_TRAININGS", "by_name"]
