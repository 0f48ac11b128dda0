"""The refusal rule's test cases: free instructions, each with its scene and what the robot says (not in the paper).

Paper, Sec. 3: PGAE-BERT reads any text and always acts; :mod:`pgae_lite.freeform.refusals` (not in the
paper) decides first whether the robot acts on a free instruction. These are the cases that rule is held
to: the unit tests check each against :func:`~pgae_lite.freeform.refusals.refusal` (an encoder without a
word lookup, so the words are read through the training lexicon), and the book's export writes them as
parity vectors for the page, which applies the same rule in the reader's browser.

Each case is a dict::

    text         the instruction as typed
    scene        the colours of the [left, right] cubes on the table, or None (only the words are judged)
    understood   the model's readback of the text (``repeat language``), or None
    says         a part of the sentence the robot refuses with, or None: it acts on the text

The cases are the explicit ones below, every paraphrase in every arrangement that has its cube, and
training phrasings (4 of each meaning, in the first arrangement that has its cube), in that order.
"""
from __future__ import annotations

import itertools

from pgae_lite.freeform.paraphrases import load_paraphrases
from pgae_lite.freeform.phrasings import phrasings
from pgae_lite.world.patterns import ARRANGEMENTS
from pgae_lite.world.words import ACTIONS, COLOURS, SPEEDS

#: The scene of the explicit cases: a red cube on the left, a blue one on the right.
SCENE = ("red", "blue")

#: Refused in :data:`SCENE`: (text, a part of the reason).
#:
#: :meta hide-value:
REFUSED = [
    ("don't push the red cube", "what not to do"),
    ("do not push the red cube, leave it alone", "what not to do"),
    ("Please never slide the blue block", "what not to do"),
    ("stop pulling the red cube", "what not to do"),
    ("push the red cube slowly and then pull the blue cube fast", "one instruction at a time"),
    ("push the red cube. After that push it again", "one instruction at a time"),
    ("push the red cube and the blue cube", "2 cubes"),
    ("push the red cube slowly and fast", "2 speeds"),
    ("push the green cube slowly", "there is no green cube here"),
    ("push the orange cube", "I know no orange cube"),
    ("push the black cube", "I know no black cube"),
    ("rotate the red cube", "I can't 'rotate' a cube"),
    ("the red cube, please", "I can push"),
    # as a phone types them (typed.normalise_typed): a curly apostrophe, a zero-width space, a soft hyphen
    ("don\u2019t push the red cube", "what not to do"),
    ("do\u200bn't push the red cube", "what not to do"),
    ("don\u00adt push the red cube", "what not to do"),
    ("\uff44\uff4f\uff4e\uff07\uff54 push the red cube", "what not to do"),
    # more than one cube, more than one act, two opposite ways, a negated speed
    ("push every cube", "more than one cube ('every')"),
    ("push both cubes slowly", "more than one cube ('both')"),
    ("pull all of them", "more than one cube ('all')"),
    ("push the two cubes", "more than one cube ('cubes')"),
    ("push the red cube twice", "more than once ('twice')"),
    ("give the red cube three pushes", "more than once ('three pushes')"),
    ("slide the blue cube back and forth", "more than once ('back and forth')"),
    ("slide the red cube left and right", "two opposite ways ('left', 'right')"),
    ("move the blue cube forward and back", "two opposite ways ('forward', 'back')"),
    ("push and pull the red cube", "2 actions"),
    ("could you please not be slow and push the red cube", "what speed not to use"),
    ("forget pushing the blue cube", "what not to do"),
    ("spin the red cube right away", "I can't 'spin' a cube"),  # "right away": a time, not the way "away"
    ("x" * 1001, "is too long"),
]

#: Acted on in :data:`SCENE`.
#:
#: :meta hide-value:
NOT_REFUSED = [
    "push the red cube, no rush",                             # a negated manner is no negation of the act
    "Please move the azure box away without hurrying",
    "push the red cube slowly, not fast",
    "go ahead and pull the red cube quickly",                 # a frame's "and" is not a second step
    "Carefully and slowly nudge the scarlet cube away from yourself",
    "don\u2019t forget to push the red cube",                 # negations that still ask for one act
    "can\u2019t you push the red cube?",
    "won't you pull the blue cube slowly?",
    "why don't you slide the red block",
    "do not hesitate to push the blue cube",
    "never mind the blue one, push the red cube",
    "forget the blue cube, pull the red one",
    "\uff50\uff55\uff53\uff48 the red cube\u00a0fast",             # fullwidth letters, a non-breaking space
    "pull the red cube back right away",                      # "right away": no side, no second way
    "push the red cube all the way forward",
]

#: Without a scene only the words are judged: (text, a part of the reason or None).
#:
#: :meta hide-value:
WITHOUT_SCENE = [
    ("push the green cube slowly", None),
    ("don't push the green cube", "what not to do"),
]

#: The readback's colour is judged whether or not the words name one: (text, readback, a part of the reason or None).
#:
#: :meta hide-value:
READBACK = [
    ("shove the thing away fast", "push yellow fast", "I understood 'push yellow fast'"),
    ("push the red cube fast", "push yellow fast", "I understood 'push yellow fast'"),   # named or not
    ("push the red cube fast", "push red fast", None),
]


def _case(text: str, scene, understood: str | None, says: str | None) -> dict:
    return {"text": text, "scene": None if scene is None else list(scene), "understood": understood, "says": says}


def refusal_cases() -> list[dict]:
    """Every case (see the module docstring), in a fixed order: the explicit ones, the paraphrases in each
    arrangement that has their cube, then 4 training phrasings of each meaning."""
    cases = [_case(text, SCENE, None, says) for text, says in REFUSED]
    cases += [_case(text, SCENE, None, None) for text in NOT_REFUSED]
    cases += [_case(text, None, None, says) for text, says in WITHOUT_SCENE]
    cases += [_case(text, SCENE, understood, says) for text, understood, says in READBACK]
    scenes = {c: [a for a in ARRANGEMENTS if c in a] for c in COLOURS}
    cases += [_case(p.text, scene, None, None) for p in load_paraphrases() for scene in scenes[p.meaning[1]]]
    for action, colour, speed in itertools.product(ACTIONS, COLOURS, SPEEDS):
        cases += [_case(text, scenes[colour][0], None, None) for text in phrasings(action, colour, speed, 4, seed=1)]
    return cases


__all__ = ["NOT_REFUSED", "READBACK", "REFUSED", "SCENE", "WITHOUT_SCENE", "refusal_cases"]
