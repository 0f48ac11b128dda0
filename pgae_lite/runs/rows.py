"""The book's trainings and rows: how each model is built, trained and measured (paper Sec. 4, Table 1; the family).

A :class:`Training` is a name (its cache folder's) and what it changes in a profile's recipe, as
values: the model's settings and parts (which model it builds follows from them,
:func:`pgae_lite.model.build.build_model`) and the training's options; and, for a model whose own
paper trained it otherwise, its authors' settings, which a profile with ``authors_recipes`` (the
``paper`` profile) uses. A :class:`Row` is one line of Table 1 or of the family's table beside it:
a training, whether it is measured on the other agent's actions, and the paper's figures, if the
paper's Table 1 has the row. Which cells a row has follows from its model (``PATHS``: N.A. where it
has no path, :func:`pgae_lite.evaluate.table1.evaluate`). Nothing anywhere branches on these names::

    | row           | training         | builds                                   | measured on            |
    |---------------|------------------|------------------------------------------|------------------------|
    | PGAE          | PGAE             | PGAE: LSTM language encoder, NICO's view  | NICO's own actions     |
    | PGAE-BERT     | PGAE-BERT        | the frozen pretrained language encoder    | NICO's own actions     |
    | PGAE-self     | PGAE-views       | NICO's or the opposite agent's view 50/50 | NICO's own actions     |
    | PGAE-opposite | PGAE-views       | the same model                            | the other agent's      |
    | PRAE, PVAE    | PRAE, PVAE       | two autoencoders bound by a loss          | per configuration      |
    | PVAE-BERT(-tuned) | ...          | PVAE on the pretrained encoder (tuned)    | per configuration      |
    | PTAE          | PTAE             | the crossmodal transformer                | NICO's own actions     |

The trainings that are no row: ``PRAE-8`` (chapter 09's one-to-many experiment), ``PGAE-no-plan``
(chapters 04 and 07), ``PGAE-BERT-phrasings`` (the free-form variant, chapters 05 and 08, A4;
chosen on validation sentences, ``experiments/validation_readback.py``, never on the test
paraphrases) and ``PGAE-BERT-phrasings-held-out`` (the same without some words, ``benchmarks/free_language.py``).
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

from pgae_lite.bert.config import PretrainedConfig
from pgae_lite.config import Profile
from pgae_lite.evaluate.table1 import PAPER_TABLE
from pgae_lite.freeform.attention_pooling import AttentionConfig
from pgae_lite.freeform.phrasing_bank import PhrasingsConfig
from pgae_lite.model.prae import BindingConfig
from pgae_lite.model.ptae import CrossmodalConfig
from pgae_lite.util.errors import ArgumentError


@dataclass(frozen=True)
class Training:
    """One training: its name (its cache folder's) and what it changes in a profile's recipe (see the module)."""

    name: str
    model: dict = field(default_factory=dict)
    train: dict = field(default_factory=dict)
    # its own authors' settings, with a profile's authors_recipes (the paper profile)
    authors_model: dict = field(default_factory=dict)
    authors_train: dict = field(default_factory=dict)
    # its authors' iterations, batch and Adam's rate: as epochs of the training samples
    authors_steps: tuple[int, int, float] | None = None

    def profile(self, base: Profile, samples: int | None = None, pretrained_model: str | None = None) -> Profile:
        """``base`` with this training's changes (``samples``: how many training samples, for a training whose
        authors counted iterations; ``pretrained_model``: the transformer of a pretrained language encoder)."""
        authors = base.authors_recipes
        model = replace(base.model, **{**self.model, **(self.authors_model if authors else {})})
        if pretrained_model and model.language is not None:
            model = replace(model, language=replace(model.language, model=pretrained_model))
        train = replace(base.train, **{**self.train, **(self.authors_train if authors else {})})
        if authors and self.authors_steps is not None:
            if samples is None:
                raise ArgumentError(f"{self.name}'s authors count iterations: give the number of training samples")
            iterations, batch, lr = self.authors_steps
            train = replace(train, epochs=max(1, round(iterations * batch / samples)), batch_size=batch, lr=lr)
        return replace(base, model=model, train=train)


# PRAE and PVAE: no plan head, and batches of any samples: the binding loss compares the codes within a batch,
# and a batch of one length never holds a slow and a fast action together. With them, PVAE described about
# half of the authors' test actions, not all (seed 0, results/family_length_batches.json).
_BOUND = {"plan_keyframes": 0}
_ANY_BATCHES = {"length_batches": False}
#: Deviation from paper (PVAE-BERT's): the encoder this project ships, frozen or its top layer tuned, not
#: BERT-base fine-tuned whole.
_PVAE = {**_BOUND, "binding": BindingConfig(variational=True, all_descriptions=True)}
_FREE_FORM = {"language": AttentionConfig(tuned_top_layer=True)}

#: Every training of the book, by name.
TRAININGS: dict[str, Training] = {t.name: t for t in (
    Training("PGAE"),
    Training("PGAE-BERT", model={"language": PretrainedConfig()}),
    # Authors' code: the opposite agent's view with probability 1/2 (describe and the repeat signals).
    Training("PGAE-views", train={"opposite_prob": 0.5}),
    # PTAE: the crossmodal transformer in place of the GMU, 128 wide in the book. Its paper's model: 256 wide,
    # feed-forward 1024, dropout 0.25, frames without positions; its training: Adam 1e-5, batch 6, 2,500 epochs.
    # Deviation from paper: at a constant rate (theirs decays in steps).
    Training("PTAE", model={"hidden": 128, "crossmodal": CrossmodalConfig()},
             authors_model={"hidden": 256, "crossmodal": CrossmodalConfig(feedforward=1024, dropout=0.25,
                                                                           frame_positions=False)},
             authors_train={"epochs": 2500}),
    # PRAE: codes of 100 (its authors'), the first of the 8 descriptions (its paper's one-to-one data);
    # its authors' code: 20,000 iterations of batch 50 at 1e-3.
    Training("PRAE", model={**_BOUND, "hidden": 100, "binding": BindingConfig()}, train=_ANY_BATCHES,
             authors_steps=(20_000, 50, 1e-3)),
    # PVAE: codes of 50, one of the 8 descriptions at random each step; 15,000 iterations of 100 at 1e-4.
    Training("PVAE", model=_PVAE, train=_ANY_BATCHES, authors_steps=(15_000, 100, 1e-4)),
    # PVAE-BERT: PVAE reading descriptions through the pretrained encoder; 40,000 iterations of 100 at 1e-4.
    Training("PVAE-BERT", model={**_PVAE, "language": PretrainedConfig()}, train=_ANY_BATCHES,
             authors_steps=(40_000, 100, 1e-4)),
    Training("PVAE-BERT-tuned", model={**_PVAE, "language": PretrainedConfig(tuned_top_layer=True)},
             train=_ANY_BATCHES, authors_steps=(40_000, 100, 1e-4)),
    # chapter 09's one-to-many experiment: PRAE reading all 8 equivalent descriptions of each action
    Training("PRAE-8", model={**_BOUND, "hidden": 100, "binding": BindingConfig(all_descriptions=True)},
             train=_ANY_BATCHES, authors_steps=(20_000, 50, 1e-3)),
    Training("PGAE-no-plan", model={"plan_keyframes": 0}),
    # the free-form variant: PGAE-BERT reading the transformer's tokens through an attention pooling, its top
    # layer tuned for free text, trained on 60 phrasings of every instruction under repeat language only: it
    # says a sentence back in the dataset's words and executes those (robot/instructions.py, "said back")
    Training("PGAE-BERT-phrasings", model=_FREE_FORM,
             train={"phrasings": PhrasingsConfig(signals=("repeat language",))}),
    Training("PGAE-BERT-phrasings-held-out", model=_FREE_FORM,
             train={"phrasings": PhrasingsConfig(signals=("repeat language",), words="held-out")}),
)}


@dataclass(frozen=True)
class Row:
    """One row of Table 1 or of the family's table: its training, whether it is measured on the other agent's
    actions (PGAE-opposite), and the paper's figures ({signal: (accuracy, nRMSE)}), if the paper's Table 1 has it."""

    name: str
    training: Training
    opposite: bool = False
    paper: dict | None = None


def _row(name: str, training: str, opposite: bool = False) -> Row:
    return Row(name, TRAININGS[training], opposite, PAPER_TABLE.get(name))


#: Table 1's rows (``reproduce --rows all``).
TABLE1_ROWS: dict[str, Row] = {r.name: r for r in (
    _row("PGAE", "PGAE"), _row("PGAE-BERT", "PGAE-BERT"), _row("PGAE-self", "PGAE-views"),
    _row("PGAE-opposite", "PGAE-views", opposite=True))}
#: The family's rows beside Table 1's (benchmarks/family.py's table; not in the paper's Table 1).
FAMILY_ROWS: dict[str, Row] = {r.name: r for r in (
    _row("PRAE", "PRAE"), _row("PVAE", "PVAE"), _row("PVAE-BERT", "PVAE-BERT"),
    _row("PVAE-BERT-tuned", "PVAE-BERT-tuned"), _row("PTAE", "PTAE"))}
#: Every row, by name.
ROWS: dict[str, Row] = {**TABLE1_ROWS, **FAMILY_ROWS}


def training_named(name: str) -> Training:
    """Any training by its name (for a command line's arguments)."""
    if name not in TRAININGS:
        raise ArgumentError(f"unknown training {name!r}; the trainings are: {', '.join(TRAININGS)}")
    return TRAININGS[name]


__all__ = ["FAMILY_ROWS", "ROWS", "Row", "TABLE1_ROWS", "TRAININGS", "Training", "training_named"]
