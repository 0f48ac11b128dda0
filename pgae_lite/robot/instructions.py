"""Free-form instructions: the model is told a sentence instead of a description, and executes it.

Paper, Sec. 3 and 5: PGAE-BERT "has the potential to recognise unseen natural
language". :func:`execute_paraphrases` gives every test episode one of the
held-out paraphrases of its own instruction (:mod:`pgae_lite.freeform.paraphrases`,
e.g. "Could you shove the crimson cube forward in a hurry" for "push red
fast") and executes it both ways, through :func:`instruction_features`
(PGAE-BERT's transformer reads any text; PGAE's LSTM only its vocabulary, and
says which words it does not know) and the paper's execute with those features
(:func:`pgae_lite.evaluate.table1.predict` with ``language=``, the open loop) as well
as :func:`pgae_lite.robot.closedloop.closed_loop`.
"""
from __future__ import annotations

import numpy as np
import pandas as pd
import torch
from tqdm.auto import tqdm

from pgae_lite.bert.pretrained import check_texts, input_text
from pgae_lite.cae import ChannelSeparatedCAE
from pgae_lite.data.dataset import PGAEDataset
from pgae_lite.data.normaliser import Normaliser
from pgae_lite.evaluate.table1 import predict
from pgae_lite.freeform.paraphrases import Paraphrase, load_paraphrases
from pgae_lite.freeform.refusals import refusal
from pgae_lite.model.pgae import PGAE
from pgae_lite.model.signals import EOS, SIGNAL_TOKEN
from pgae_lite.robot.closedloop import execute_episode, spread, variation_of
from pgae_lite.sim.dataset import DatasetConfig
from pgae_lite.util.checks import whole_number
from pgae_lite.world.patterns import Pattern
from pgae_lite.world.words import WORD_INDEX, LanguageError, parse_description, signal_index, tokenize


@torch.no_grad()
def instruction_features(model: PGAE, texts: list[str]) -> torch.Tensor:
    """Instructions -> the language encoder's features under ``execute``, (B, D), for ``language=``.

    PGAE-BERT's pretrained encoder reads any text, after the signal phrase
    (``input_text("execute", text)``, as in training). PGAE's LSTM reads only
    its vocabulary: every text must be a description (action colour speed),
    else a :class:`~pgae_lite.world.words.LanguageError` names the unknown words.
    """
    texts, encoder = check_texts("instruction_features", texts), model.language_encoder
    if not texts:
        raise LanguageError("instruction_features takes at least one instruction; got an empty list")
    if encoder.reads_free_text:                                   # PGAE-BERT
        return encoder.encode_texts([input_text("execute", t) for t in texts])
    for t in texts:
        try:
            parse_description(t)
        except LanguageError as e:
            raise LanguageError(f"PGAE's LSTM language encoder reads only its vocabulary, in the order "
                                f"action colour speed (PGAE-BERT reads free text): {e}") from e
    device = next(model.parameters()).device
    tokens = torch.tensor([[SIGNAL_TOKEN + signal_index("execute"), *(WORD_INDEX[w] for w in tokenize(t)), EOS]
                           for t in texts], device=device)                                   # (B, 5)
    return encoder(tokens, torch.full((len(texts),), 5, device=device))


ROUTES = ("direct", "said back")
#: The message of :func:`check_route`'s error as a template (``str.format``, named fields); the page fills it too.
MESSAGES: dict[str, str] = {"unknown_route": "unknown route {route}; the options are: {routes}"}


def check_route(route: str) -> None:
    """A ValueError naming the routes unless ``route`` is one of ``ROUTES``."""
    if route not in ROUTES:
        raise ValueError(MESSAGES["unknown_route"].format(route=repr(route), routes=", ".join(map(repr, ROUTES))))


@torch.no_grad()
def say_back(model: PGAE, data: PGAEDataset, normaliser: Normaliser, texts: list[str]) -> list[str]:
    """Each instruction said back in the dataset's words (``repeat language``; sample i of ``data``
    carries text i, whose action the model is not shown), e.g. ``"push red fast"``."""
    texts = check_texts("say_back", texts)
    if not model.language_encoder.reads_free_text:
        raise ValueError("saying back free text needs PGAE-BERT's pretrained encoder; PGAE's LSTM reads "
                         "descriptions only")
    language = model.language_encoder.encode_texts([input_text("repeat language", t) for t in texts])
    return predict(model, data, normaliser, "repeat language", language=language).text


def acted_on(said: list[str], texts: list[str]) -> list[str]:
    """What ``route="said back"`` executes: the words said back where they are a description
    (action colour speed; hyphens read as spaces), else the instruction itself."""
    if len(said) != len(texts):
        raise ValueError(f"acted_on needs one readback per instruction; got {len(said)} readbacks "
                         f"for {len(texts)} instructions")
    out = []
    for back, text in zip(said, texts):
        try:
            parse_description(back)
            out.append(back.replace("-", " "))   # "move up", as training wrote it for the transformer
        except LanguageError:
            out.append(text)
    return out


def default_route(profile) -> str | None:
    """The route free text takes under execute unless told otherwise, from the recipe ``profile`` the model
    was trained with: ``"said back"`` for a model that read free text in training, but never under
    execute (the free-form variant: it executes its own readback, which it was trained to write);
    ``"direct"`` for one that reads free text otherwise (the paper's PGAE-BERT); None for a model that
    reads no free text (PGAE's LSTM)."""
    if profile.model.language is None:
        return None
    phrasings = profile.train.phrasings
    return "said back" if phrasings is not None and "execute" not in phrasings.signals else "direct"


def paraphrase_of(pattern: int, variation: int, paraphrases: list[Paraphrase]) -> Paraphrase | None:
    """The paraphrase an episode is given: of its pattern's meaning, number ``variation`` mod how many there are.

    With the 3 paraphrases per test instruction and 6 variations, each is used twice.
    None: no paraphrase has that meaning.
    """
    pat = Pattern.from_number(pattern)
    mine = [p for p in paraphrases if p.meaning == (pat.action, pat.colour, pat.speed)]
    return mine[variation % len(mine)] if mine else None


def execute_paraphrases(model: PGAE, cae: ChannelSeparatedCAE, normaliser: Normaliser, data: PGAEDataset,
                        paraphrases: list[Paraphrase] | None = None, split: str = "test", *,
                        limit: int | None = None, closed: bool = True, config: DatasetConfig | None = None,
                        tracking: bool = True, progress: bool = True, route: str = "direct") -> pd.DataFrame:
    """Free-form instructions executed in their episodes' scenes, open and closed loop; one row per episode.

    Every episode of ``split`` whose meaning has a paraphrase (default: the 108 of
    :func:`~pgae_lite.freeform.paraphrases.load_paraphrases`) is told one
    (:func:`paraphrase_of`), encoded by :func:`instruction_features`: PGAE-BERT
    reads it, PGAE's LSTM raises a LanguageError naming the unknown words before
    anything runs. Then, as in :func:`~pgae_lite.robot.closedloop.compare`: the paper's
    execute (:func:`~pgae_lite.evaluate.table1.predict` with ``language=``) run in the
    simulator (``open_*`` columns) and, if ``closed``,
    :func:`~pgae_lite.robot.closedloop.closed_loop` (``closed_*``). nRMSE (%) is against
    the recorded joints of the episode, the intended action. ``limit``: that many
    episodes, evenly spread. ``route``: ``"direct"`` (the paper's: the instruction's
    features) or ``"said back"`` (:func:`say_back`, then those words; the ``acted_on``
    column). Instructions the robot will not act on (:mod:`pgae_lite.freeform.refusals`: a negation,
    more than one instruction, a cube not in the episode's scene, ...) are not executed: their
    ``refused`` column says why (it is empty for the others).
    """
    check_route(route)
    if limit is not None:
        whole_number("limit", limit, 1)
    if closed and cae is None:
        raise ValueError("the closed loop needs the CAE (cae=...), which reads each step's camera image; "
                         "give it, or pass closed=False for the open loop only")
    paraphrases = load_paraphrases() if paraphrases is None else paraphrases
    subset = data.split(split)
    told = [paraphrase_of(int(p), variation_of(i), paraphrases) for p, i in zip(subset.pattern, subset.ids)]
    rows = np.flatnonzero([t is not None for t in told])
    if not len(rows):
        raise ValueError(f"no paraphrase has the meaning of any {split} episode")
    rows = rows[spread(len(rows), limit)]
    episodes, told = subset.subset(rows), [told[i] for i in rows]
    texts = [t.text for t in told]
    language = instruction_features(model, texts)                             # (N, D); PGAE's LSTM: refused here
    said, refused = [None] * len(texts), [None] * len(texts)      # PGAE's LSTM: descriptions, none refused
    if model.language_encoder.reads_free_text:
        said = say_back(model, episodes, normaliser, texts)
        refused = [refusal(text, model.language_encoder, scene_of(int(p)), back)   # freeform/refusals.py
                   for text, p, back in zip(texts, episodes.pattern, said)]
    if route == "said back":
        texts = acted_on(said, texts)
        language = instruction_features(model, texts)
    planned = predict(model, episodes, normaliser, "execute", language=language).joints   # the paper's execute
    joint_range = data.joint_range()
    rows = []
    for k in tqdm(range(len(episodes)), desc="paraphrases", unit="ep", disable=not progress):
        row = {"id": episodes.ids[k], "pattern": int(episodes.pattern[k]), "description": told[k].text} \
            if refused[k] else execute_episode(model, cae, normaliser, episodes, k, planned[k], told[k].text,
                                               joint_range, language=language[k:k + 1], closed=closed,
                                               config=config, tracking=tracking)
        rows.append({**row, "meaning": " ".join(told[k].meaning), "acted_on": texts[k], "refused": refused[k] or ""})
    return pd.DataFrame(rows)


def scene_of(pattern: int) -> tuple[str, str]:
    """The colours of the (left, right) cubes in ``pattern``'s scene."""
    p = Pattern.from_number(pattern)
    return p.left, p.right


__all__ = ["ROUTES", "check_route", "default_route", "instruction_features", "say_back", "acted_on", "paraphrase_of",
           "execute_paraphrases", "scene_of"]
