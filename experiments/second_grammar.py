"""A second grammar for validation: instructions in sentence forms the training grammar never writes.

Not from the paper. The training phrasings (:mod:`pgae_lite.freeform.phrasings`) say an
instruction as an imperative clause inside politeness frames and carriers. A
validation set drawn from that same grammar (``validation_readback.py``'s
default) rewards a model for learning the grammar, not the language: at
``1a5fe47`` it no longer told the tuned top layer from the untuned variant on
held-out words, though the test paraphrases did. This grammar says the same 36
meanings, with the lexicon's words for action, colour and speed
(:data:`pgae_lite.freeform.phrase_lexicon.LEXICON`, held-out words included), in other
forms: passives (``the red cube needs to be pushed away``), wanted end states
(``I want the red cube closer to you``), the cube as subject of ``go``, questions
of possibility, two steps (``reach for ..., then ...``), the speed as its own
sentence. Written for validation only, before looking at any test sentence, and
never used in training.

    python experiments/second_grammar.py push red fast 6
"""
from __future__ import annotations

import argparse
import random
import re

from pgae_lite.freeform.phrase_lexicon import LEXICON, MEANINGS, SLOTS
from pgae_lite.freeform.phrasings import gerund

#: Past participles the -ed rule gets wrong.
_IRREGULAR = {"thrust": "thrust", "draw": "drawn", "slide": "slid", "sweep": "swept",
              "bring": "brought", "send": "sent", "take": "taken", "get": "gotten"}


def participle(verb: str) -> str:
    """``push`` -> ``pushed``, ``glide`` -> ``glided``, ``drag`` -> ``dragged``, ``draw`` -> ``drawn``.

    The -ing form's stem (:func:`pgae_lite.freeform.phrasings.gerund`: ``dragg``, ``glid``) plus ``ed``."""
    return _IRREGULAR.get(verb) or gerund(verb)[:-len("ing")] + "ed"


def _action(action: str, rng: random.Random) -> tuple[str, str]:
    """A verb and a direction that together say ``action``; the direction may be ``""`` after an action verb."""
    lex = LEXICON
    if rng.random() < 0.55:
        verb = rng.choice(lex.verbs[action])
        return verb, rng.choice(lex.directions[action]) if rng.random() < 0.5 else ""
    verb = rng.choice(lex.neutral + lex.steered[action])
    return verb, rng.choice(lex.directions[action])


def _cube(colour: str, rng: random.Random) -> str:
    """The cube, with the colour before or after its noun."""
    name, noun = rng.choice(LEXICON.colours[colour]), rng.choice(LEXICON.nouns)
    return rng.choice((f"the {name} {noun}",) * 4 + (
        f"the {noun} that looks {name}", f"whichever {noun} is {name}",
        f"the {name} {noun} on the table", f"the {noun} painted {name}"))


def sentence(action: str, colour: str, speed: str, rng: random.Random) -> str:
    """One sentence of (action, colour, speed) in a form of this grammar."""
    verb, d = _action(action, rng)
    cube, how = _cube(colour, rng), rng.choice(LEXICON.speeds[speed])
    adj = rng.choice(LEXICON.adjectives[speed])
    way = d or rng.choice(LEXICON.directions[action])       # forms that need a direction
    goal = rng.choice([w for w in LEXICON.directions[action] if " " in w or w.endswith("er")])
    forms = [
        f"{cube} {rng.choice(('needs to', 'has to', 'should', 'must'))} be {participle(verb)} {d} {how}",
        f"I want {cube} {participle(verb)} {d} {how}",
        f"what I need is for {cube} to be {participle(verb)} {d} {how}",
        f"{cube} should go {way}, {how}",
        f"I want {cube} {goal}, and {how}",
        f"is it possible to {verb} {cube} {d} {how}?",
        f"is there a way you could {verb} {cube} {d} {how}?",
        f"reach for {cube}, then {verb} it {d} {how}",
        f"first take hold of {cube}, then {verb} it {d} {how}",
        f"the one to move is {cube}: {verb} it {d} {how}",
        f"{verb} {cube} {d}. {how}, please",
        f"{verb} {cube} {d}, and be {adj} about it",
        f"a {adj} one, please: {verb} {cube} {d}",
        f"{verb} {cube} {d}. keep it {adj}",
    ]
    text = rng.choice(forms)
    text = re.sub(r"\s+([,.:?])", r"\1", re.sub(r"\s+", " ", text)).strip()
    text = re.sub(r"\. ([a-z])", lambda m: ". " + m.group(1).upper(), text)
    return text[0].upper() + text[1:] + ("" if text.endswith("?") else rng.choice(("", ".", "!")))


def second_phrasings(action: str, colour: str, speed: str, n: int, seed: int = 0) -> list[str]:
    """``n`` distinct sentences for one meaning; the same seed gives the same list."""
    for slot, value in zip(SLOTS, (action, colour, speed)):
        if value not in MEANINGS[slot]:
            raise ValueError(f"{slot} {value!r} is not one of: {', '.join(MEANINGS[slot])}")
    rng = random.Random(f"second {seed} {action} {colour} {speed}")
    found: dict[str, None] = {}
    for _ in range(50 * n):
        found[sentence(action, colour, speed, rng)] = None
        if len(found) == n:
            return list(found)
    raise ValueError(f"only {len(found)} distinct sentences for {action} {colour} {speed}, not {n}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("action", help="push, pull or slide")
    parser.add_argument("colour", help="one of the six cube colours, e.g. red")
    parser.add_argument("speed", help="slowly or fast")
    parser.add_argument("n", type=int, help="how many distinct sentences")
    args = parser.parse_args()
    print("\n".join(second_phrasings(args.action, args.colour, args.speed, args.n)))
