"""A small grammar of free instructions in six classes, for measuring the refusal rule (not in the paper).

Paper, Sec. 3: PGAE-BERT reads any text and always acts; :mod:`pgae_lite.freeform.refusals` (not in the
paper) decides first whether the robot acts. This grammar, written from general English and not from the
model's phrase lexicon, tells a table of two cubes five kinds of instruction the robot must refuse and one
it must act on (``benchmarks/refusals.py`` measures the shares; the book's export writes some of each as
parity vectors for the page, :mod:`pgae_lite.web.parity`)::

    negation        "don't push the red cube", "you must not drag the blue block", ...
    more_than_one   two instructions, "push the red cube, then pull the blue one", ...
    absent_cube     an instruction for a colour of the world that is not on the table
    outside_colour  a colour the world does not have ("the orange cube", "the black box")
    outside_action  an action the robot cannot do ("lift", "rotate", "throw", ...)
    valid           one instruction for a cube on the table
"""
from __future__ import annotations

import random

from pgae_lite.world.words import COLOURS

# The grammar: verbs "{}" around the object, by action; objects; manners; openings.
VERBS = {"push": ("push {}", "shove {}", "poke {} away", "move {} away from you", "nudge {} forward",
                  "knock {} forward", "send {} away"),
         "pull": ("pull {}", "drag {}", "bring {} back toward you", "haul {} closer", "yank {} back",
                  "draw {} in", "move {} nearer to you"),
         "slide": ("slide {}", "move {} to the side", "scoot {} sideways", "slide {} across", "shift {} aside",
                   "glide {} over")}
GERUNDS = {"push": "pushing {}", "pull": "pulling {}", "slide": "sliding {}"}
OBJECTS = ("the {} cube", "the {} block", "that {} one", "the {} box", "the {} thing")
MANNERS = ("", "slowly", "quickly", "fast", "gently", "in a hurry", "carefully", "at a snail's pace",
           "right away", "with a bit of speed")
OPENINGS = ("", "please ", "could you ", "now ", "I'd like you to ", "robot, ", "go on and ")
NEGATIONS = ("don't {v}", "do not {v}", "never {v}", "please don't {v}", "you must not {v}", "stop {g}",
             "avoid {g}", "I don't want you to {v}", "no, don't {v}", "do not ever {v}")
SEQUENCES = ("{a} and then {b}", "{a}, then {b}", "first {a}, after that {b}", "{a} and {b}", "{a}. {b} too",
             "{a}; afterwards {b}")
OUTSIDE_COLOURS = ("orange", "pink", "brown", "black", "white", "grey", "beige", "silver", "tan", "ivory",
                   "bronze", "khaki")
OUTSIDE_ACTIONS = ("lift {}", "rotate {}", "throw {}", "stack {}", "spin {}", "flip {} over", "grab {}",
                   "pick up {}", "knock {} over", "squeeze {}", "paint {}", "turn {} around", "hide {}",
                   "open {}", "smash {}")
CLASSES = ("negation", "more_than_one", "absent_cube", "outside_colour", "outside_action", "valid")


def sentence(kind: str, scene: tuple[str, str], rng: random.Random) -> str:
    """One sentence of class ``kind`` for a table with the cubes ``scene``."""
    here = rng.choice(scene)
    action = rng.choice(tuple(VERBS))
    obj = rng.choice(OBJECTS).format(here)
    manner = rng.choice(MANNERS)

    def said(verb: str, thing: str) -> str:
        return f"{verb.format(thing)} {manner}".strip()

    if kind == "negation":
        text = rng.choice(NEGATIONS).format(v=said(rng.choice(VERBS[action]), obj),
                                            g=said(GERUNDS[action], obj))
    elif kind == "more_than_one":
        other = rng.choice([a for a in VERBS if a != action] + [action])
        second = rng.choice(OBJECTS).format(scene[1] if here == scene[0] else scene[0])
        text = rng.choice(SEQUENCES).format(a=said(rng.choice(VERBS[action]), obj),
                                            b=said(rng.choice(VERBS[other]), second))
    elif kind == "absent_cube":
        text = said(rng.choice(VERBS[action]), rng.choice(OBJECTS).format(
            rng.choice([c for c in COLOURS if c not in scene])))
    elif kind == "outside_colour":
        text = said(rng.choice(VERBS[action]), rng.choice(OBJECTS).format(rng.choice(OUTSIDE_COLOURS)))
    elif kind == "outside_action":
        text = said(rng.choice(OUTSIDE_ACTIONS), obj)
    else:
        text = said(rng.choice(VERBS[action]), obj)
    return rng.choice(OPENINGS) + text


__all__ = ["CLASSES", "sentence"]
