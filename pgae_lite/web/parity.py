"""Parity vectors: what Python computes for the page's inputs, written at export (not in the paper).

Paper, Sec. 3 and 4, as :func:`pgae_lite.robot.playground.play` computes them. The page
(``book/_js/pgae-logic.js``, ``pgae-refusals.js``, ``pgae.js``) re-computes in JavaScript what
the reader's choices mean: a typed text read, an episode picked, a batch built, words and how sure
the decoder was, a refusal, a route, a verdict. Python writes here what each of those must give,
and ``tests/test_page_logic.py`` runs the page's JavaScript against them in a headless browser,
with no book build. Every entry is an input and Python's answer (its value, or its error message)::

    repr       a string -> Python's repr (the page quotes the reader's text as Python does)
    typed      (model, signal, text) -> read_typed's words and meaning, or its error
    batches    (episode, signal, words) -> the graph's inputs (episode_inputs of make_batch)
    readings   (model, text) -> the text as the model reads it, and the words its lookup replaced
    refusals   (model, text, scene, readback) -> the refusal's sentence, or None; every case of
               pgae_lite.freeform.refusal_cases, the paraphrases, and 40 sentences of each class of
               pgae_lite.freeform.refusal_grammar
    choices    logits -> word_choices (how sure of each word)
    plays      (model, the page's run arguments) -> play's result (loop=None), or its error

The texts are general English, the refusal rule's own test cases and hostile strings, never a
held-out evaluation sentence.
"""
from __future__ import annotations

import json
import random
from pathlib import Path

import numpy as np
import torch

from pgae_lite.freeform.paraphrases import load_paraphrases
from pgae_lite.freeform.refusal_cases import refusal_cases
from pgae_lite.freeform.refusal_grammar import CLASSES, sentence
from pgae_lite.freeform.refusals import refusal
from pgae_lite.model.signals import make_batch, signal_ids
from pgae_lite.robot.instructions import default_route
from pgae_lite.robot.play_result import word_choices
from pgae_lite.robot.playground import PLAY_SIGNALS, play
from pgae_lite.robot.typed_text import read_typed
from pgae_lite.util.errors import PGAELiteError
from pgae_lite.util.storage import atomic_write_text
from pgae_lite.web.export import episode_inputs
from pgae_lite.world.patterns import ARRANGEMENTS
from pgae_lite.world.words import COLOURS, WORD_INDEX, equivalent_descriptions

#: Strings the page must quote as Python does: quotes, escapes, what a phone types, other scripts.
HOSTILE = ["push red slowly", "don't push", "say \"hi\"", "both ' and \"", "back\\slash", "tab\tand\nline",
           "don\u2019t push the red cube", "push\u200b the red cube", "\uff50\uff55\uff53\uff48 red", "caf\u00e9",
           "\U0001F916 push", "bell\x07", "\x85next\u2028line", "\u00a0spaces\u3000", "", "'", "\"", "\\"]
#: Texts typed for a model, read or refused as read_typed reads them.
TYPED = ["push red slowly", "Move Up blonde quickly!", "move-up red fast", "yellow push fast", "push red",
         "push red slowly please", "push the red cube slowly", "shove the scarlet block away",
         "<BOS/EOS> pull blue fast", "PUSH, red; slowly.", "push  red\tslowly", "blorp fizz wug",
         "Schieb den roten W\u00fcrfel langsam", "\U0001F916\U0001F7E5", "don\u2019t push the red cube",
         "\uff50\uff55\uff53\uff48 red slowly", "   "]
#: Free instructions for the plays: kinds a reader tries (valid, refused, nonsense, other languages).
FREE = ["please push the {left} cube slowly", "could you nudge the {right} block to the side quickly",
        "don't push the {left} cube", "push the {absent} cube", "slide the {left} block, then pull the {right} one",
        "blorp fizz wug", "Schieb den roten W\u00fcrfel langsam", "\U0001F916\U0001F7E5\u27A1\uFE0F",
        "do not touch anything"]


def _error(call):
    """(call's value, None), or (None, the message of the reader's error it raised)."""
    try:
        return call(), None
    except (ValueError, TypeError, PGAELiteError) as e:
        return None, str(e)


def _typed(trained: dict) -> list[dict]:
    out = []
    for name, run in trained.items():
        for signal in PLAY_SIGNALS:
            for text in TYPED:
                typed, error = _error(lambda: read_typed(run.model.language_encoder, signal, text.strip()))
                out.append({"model": name, "signal": signal, "text": text.strip(), "error": error,
                            "words": list(typed.words) if typed and typed.words else None,
                            "meaning": list(typed.meaning) if typed and typed.meaning else None})
    return out


def _batches(data, normaliser, episodes: list[dict]) -> list[dict]:
    """The graph's inputs for two of the page's episodes (a test and a training one) under each signal."""
    rows = {str(i): k for k, i in enumerate(data.ids)}
    picked = [next(e for e in episodes if e["split"] == split) for split in ("test", "train")]
    out = []
    for episode in picked:
        for signal in PLAY_SIGNALS:
            for words in (None, ["move-up", "blonde", "quickly"]):
                tensors = normaliser.tensors(data.subset(np.array([rows[episode["id"]]])))
                if words:                                                 # the reader's words replace the episode's
                    tensors["descriptions"][:] = torch.tensor([WORD_INDEX[w] for w in words])
                zero = torch.zeros(1, dtype=torch.long)
                x = episode_inputs(make_batch(tensors, zero, signal_ids(signal, 1), zero), 0)
                out.append({"episode": episode["id"], "signal": signal, "words": words,
                            "tokens": x["language"][0].tolist(), "action_steps": int(x["action_input"].shape[1]),
                            "dec": x["dec_vision"].ravel().tolist(), "start": x["start"].ravel().tolist()})
    return out


def _readings(encoders: dict, texts: list[str]) -> list[dict]:
    out = []
    for name, encoder in encoders.items():
        lookup = encoder.word_lookup
        for text in texts:
            swapped = lookup.replacements(text) if lookup is not None else {}
            out.append({"model": name, "text": text, "read": encoder.read_as(text),
                        "replacements": [[w, r] for w, r in swapped.items()]})
    return out


def _grammar(per_class: int = 40, seed: int = 0) -> list[dict]:
    """``per_class`` sentences of each class of the refusal grammar, each told in a random arrangement."""
    rng = random.Random(seed)
    return [{"text": sentence(kind, scene, rng), "scene": list(scene), "understood": None}
            for kind in CLASSES for scene in (rng.choice(ARRANGEMENTS) for _ in range(per_class))]


def _refusals(encoders: dict) -> list[dict]:
    cases = refusal_cases() + [{"text": p.text, "scene": None, "understood": None} for p in load_paraphrases()]
    cases += _grammar()
    return [{"model": name, "text": c["text"], "scene": c["scene"], "understood": c["understood"],
             "message": refusal(c["text"], encoder, tuple(c["scene"]) if c["scene"] else None, c["understood"])}
            for name, encoder in encoders.items() for c in cases]


def _choices(seed: int = 0, count: int = 12) -> list[dict]:
    gen = torch.Generator().manual_seed(seed)
    logits = [torch.randn(4, len(WORD_INDEX), generator=gen) * scale for scale in np.linspace(0.2, 8, count)]
    return [{"logits": x.tolist(), "choices": word_choices(x)} for x in logits]


def play_cases(episodes: list[dict], free: bool) -> list[dict]:
    """The page's run arguments whose results Python computes: each signal on a test and a training episode, typed
    descriptions that pick their episode or are refused, bad arguments, and (``free``) free text by both routes."""
    first = {split: next(e for e in episodes if e["split"] == split) for split in ("test", "train")}
    cases = [{"signal": s, "arrangement": e["arrangement"], "action": e["action"], "variation": 0}
             for e in first.values() for s in PLAY_SIGNALS]
    e = first["test"]
    left, right = ARRANGEMENTS[e["arrangement"]]
    absent = next(c for c in COLOURS if c not in (left, right))
    action, colour, speed = e["meaning"]
    other = "fast" if speed == "slowly" else "slowly"
    texts = [e["description"], " ".join(equivalent_descriptions(action, colour, speed)[-1]),
             f"{action} {right if colour == left else left} {other}", f"pull {absent} slowly", "yellow push fast"]
    place = {"arrangement": e["arrangement"], "action": e["action"]}
    cases += [{"signal": s, **place, "text": t} for s in ("execute", "repeat language", "describe") for t in texts]
    if free:
        said = [t.format(left=left, right=right, absent=absent) for t in FREE]
        cases += [{"signal": s, **place, "text": t, **({"route": r} if r else {})}
                  for t in said for s, r in (("execute", "direct"), ("execute", "said back"), ("execute", None),
                                             ("repeat language", None))]
    bad = [{"arrangement": 12, "action": 0}, {"arrangement": 0, "action": -1}, {"arrangement": 1.5, "action": 0},
           {"arrangement": "3", "action": 0}]
    cases += [{"signal": "execute", **b} for b in bad]
    cases += [{"signal": "dance", **place}, {**place, "signal": "execute", "variation": 99},
              {**place, "signal": "execute", "text": e["description"], "route": "sideways"}]
    return cases


def _result(r) -> dict:
    """A PlayResult as the page returns it (its arrays as lists)."""
    return {"signal": r.signal, "pattern": r.pattern, "variation": r.variation, "episode": r.episode, "told": r.told,
            "words": r.words, "correct": bool(r.correct), "understood": r.understood, "note": r.note,
            "route": r.route, "acted_on": r.acted_on, "choices": r.choices, "understood_choices": r.understood_choices,
            "joints": r.joints.tolist(), "target": r.target.tolist(), "nrmse": r.nrmse, "gate": r.gate.tolist()}


def _plays(trained: dict, data, episodes: list[dict]) -> list[dict]:
    out = []
    for name, run in trained.items():
        free = run.model.language_encoder.reads_free_text
        for args in play_cases(episodes, free):
            route = args.get("route", default_route(run.profile) or "direct")     # the page's default: the model's
            result, error = _error(lambda: play(run.model, None, run.normaliser, data, args["signal"],
                                                args["arrangement"], args["action"], args.get("text"),
                                                variation=args.get("variation", 0), loop=None, route=route))
            out.append({"model": name, "args": args, "error": error, "result": _result(result) if result else None})
    return out


def write_parity(out: str | Path, trained: dict, data, normaliser, episodes: list[dict]) -> dict:
    """Write ``out/parity.json`` (see the module docstring) for the page's models ``trained`` (name -> the
    pipeline's trained model), the dataset ``data`` and the page's ``episodes`` index; return its counts."""
    encoders = {name: run.model.language_encoder for name, run in trained.items()
                if run.model.language_encoder.reads_free_text}
    texts = [c["text"] for c in refusal_cases()] + TYPED + HOSTILE
    vectors = {"repr": [[s, repr(s)] for s in HOSTILE + TYPED], "typed": _typed(trained),
               "batches": _batches(data, normaliser, episodes), "readings": _readings(encoders, texts),
               "refusals": _refusals(encoders), "choices": _choices(), "plays": _plays(trained, data, episodes)}
    atomic_write_text(Path(out) / "parity.json", json.dumps(vectors))
    return {kind: len(v) for kind, v in vectors.items()}


__all__ = ["FREE", "HOSTILE", "TYPED", "play_cases", "write_parity"]
