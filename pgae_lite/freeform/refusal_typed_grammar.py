"""Typed variants of free instructions, in two sets of templates, for measuring the refusal rule (not in the paper).

Paper, Sec. 3: PGAE-BERT reads any text and always acts; :mod:`pgae_lite.freeform.refusals` (not in the
paper) decides first whether the robot acts. :mod:`pgae_lite.freeform.refusal_grammar` measures it on plain
English; this grammar measures what issue 62 found: text as a phone types it, polite negations, words over
several cubes, repetitions, opposite ways and verbs the world lacks behind the word lookup. Its templates
come in two sets, written before the rule was measured on either and kept apart:

    development   the set the rule was checked on while it was written
    held-out      other templates, other words and other marks, never used to change the rule

Each set has the same eight classes, each marked by what the robot must do::

    unicode_negation   refuse   a negation typed with other apostrophes, zero-width or fullwidth characters
    unicode_valid      act      one instruction typed with other spaces, marks and fullwidth letters
    polite_negation    act      a negation that still asks for one action ("can't you ...?", "never mind X, ...")
    quantifier         refuse   a word over several cubes ("every", "both", "the two cubes")
    repetition         refuse   the act more than once ("twice", "three times", "again and again")
    opposite_ways      refuse   two opposite directions joined ("left and right", "forward and back")
    absent_verb        refuse   a verb of no action of the world ("lift", "throw"), whatever the lookup reads
    valid              act      one plain instruction for a cube on the table
"""
from __future__ import annotations

import random

from pgae_lite.util.errors import ArgumentError

#: What the robot must do with each class.
REFUSE = ("unicode_negation", "quantifier", "repetition", "opposite_ways", "absent_verb")
ACT = ("unicode_valid", "polite_negation", "valid")
CLASSES = REFUSE + ACT
SETS = ("development", "held-out")

# Per set: verbs "{}" around the object (by action), objects, manners, and each class's templates
# ({v}: a verb with its object, {o}: an object, {x}: another cube's object, {m}: a manner).
_SETS = {
    "development": {
        "verbs": {"push": ("push {}", "shove {} away", "move {} away from you"),
                  "pull": ("pull {}", "drag {} toward you", "bring {} closer"),
                  "slide": ("slide {}", "slide {} to the side", "move {} sideways")},
        "objects": ("the {} cube", "the {} block", "that {} one"),
        "manners": ("", "slowly", "fast", "quickly"),
        "marks": {"'": ("\u2019",), "space": ("\u00a0",), "inside": ("\u200b",)},
        "fullwidth": True,
        "unicode_negation": ("don'{zw}t {v}", "please don't {v}", "you mustn't {v}", "I don't want you to {v}"),
        "unicode_valid": ("{v}", "please {v}", "\u201c{v}\u201d", "could you {v}?"),
        "polite_negation": ("can't you {v}?", "don't forget to {v}", "never mind {x}, {v}"),
        "quantifier": ("push every cube", "pull both cubes", "slide all the cubes {m}", "push the two cubes"),
        "repetition": ("{v} twice", "{v} three times", "{v} again and again"),
        "opposite_ways": ("slide {o} left and right", "move {o} forward and back"),
        "absent_verbs": ("lift {}", "throw {}", "rotate {}", "flip {}", "squeeze {}", "raise {}"),
    },
    "held-out": {
        "verbs": {"push": ("nudge {} forward", "send {} away", "propel {} ahead"),
                  "pull": ("tug {} back", "draw {} nearer", "haul {} in close"),
                  "slide": ("shift {} aside", "glide {} across", "scoot {} over to the side")},
        "objects": ("the {} box", "the {} brick", "this {} block", "the {} toy block"),
        "manners": ("", "gently", "swiftly", "at top speed", "little by little"),
        "marks": {"'": ("\u02bc", "\u2032", "\u00b4", "\uff07", "\u2018"),
                  "space": ("\u2003", "\u3000", "\u202f", "\u2009"),
                  "inside": ("\u00ad", "\u2060", "\ufeff", "\u200d")},
        "fullwidth": True,
        "unicode_negation": ("do{zw}n't ever {v}", "robot, never {v}", "you shouldn't {v}", "no, don't {v}",
                             "I'd rather you didn't {v}", "please do not {v}"),
        "unicode_valid": ("ok \u2013 {v}", "\u00ab{v}\u00bb", "{v}, thanks", "now {v} \u2014 please",
                          "would you {v}?"),
        "polite_negation": ("won't you {v}?", "couldn't you {v}?", "wouldn't you {v}", "do not hesitate to {v}",
                            "don't neglect to {v}", "never fail to {v}", "forget {x}; {v}", "ignore {x} and {v}",
                            "why don't you {v}?", "oh never mind {x}, just {v}"),
        "quantifier": ("nudge each cube forward", "tug either of the blocks back", "shift both of the boxes aside",
                       "send them all away {m}", "glide the two blocks across", "draw any of the cubes nearer"),
        "repetition": ("{v} thrice", "{v} four times", "{v} a few times", "{v} over and over",
                       "give {o} two quick shoves", "{v} repeatedly"),
        "opposite_ways": ("shift {o} to the left and to the right", "move {o} up and down",
                          "move {o} away and toward you", "send {o} back or forward"),
        "absent_verbs": ("hurl {}", "toss {}", "fling {}", "elevate {}", "hoist {}", "twist {}", "kick {}",
                         "carry {}", "shake {}", "tip {} over", "roll {}", "bounce {}"),
    },
}

#: Fullwidth forms of the ASCII letters (NFKC reads them as the letters).
_FULLWIDTH = {c: chr(ord(c) - ord("a") + 0xFF41) for c in "abcdefghijklmnopqrstuvwxyz"}


def _marked(text: str, marks: dict, rng: random.Random, fullwidth: bool) -> str:
    """``text`` with its apostrophes, some spaces and one word typed otherwise."""
    text = text.replace("'", rng.choice(marks["'"]))
    words = text.split(" ")
    for i in range(1, len(words)):
        if rng.random() < 0.3:
            words[i] = rng.choice(marks["space"]) + words[i]
        else:
            words[i] = " " + words[i]
    text = "".join(words)
    if fullwidth and rng.random() < 0.5:
        word = rng.choice([w for w in text.split() if w.isascii() and w.isalpha()] or [""])
        text = text.replace(word, "".join(_FULLWIDTH.get(c, c) for c in word), 1) if word else text
    return text


def typed_sentence(kind: str, scene: tuple[str, str], rng: random.Random, which: str = "held-out") -> str:
    """One sentence of class ``kind`` of template set ``which`` for a table with the cubes ``scene``."""
    if which not in _SETS:
        raise ArgumentError(f"template set {which!r} is not one of: {', '.join(SETS)}")
    if kind not in CLASSES:
        raise ArgumentError(f"class {kind!r} is not one of: {', '.join(CLASSES)}")
    g = _SETS[which]
    here = rng.choice(scene)
    other = scene[1] if here == scene[0] else scene[0]
    obj, manner = rng.choice(g["objects"]).format(here), rng.choice(g["manners"])
    verb = rng.choice(g["verbs"][rng.choice(tuple(g["verbs"]))]).format(obj)
    said = f"{verb} {manner}".strip()
    zw = rng.choice(g["marks"]["inside"])
    fill = {"v": said, "o": obj, "x": rng.choice(g["objects"]).format(other), "m": manner, "zw": zw}
    if kind == "absent_verb":
        return f"{rng.choice(g['absent_verbs']).format(obj)} {manner}".strip()
    if kind == "valid":
        return said
    text = rng.choice(g[kind]).format(**fill).replace("  ", " ").strip()
    if kind in ("unicode_negation", "unicode_valid"):
        text = _marked(text, g["marks"], rng, g["fullwidth"])
    return text


__all__ = ["ACT", "CLASSES", "REFUSE", "SETS", "typed_sentence"]
