"""What the robot will not do with a free instruction, and says instead (not in the paper).

Paper, Sec. 3: PGAE-BERT "has the potential to recognise unseen natural language",
and whatever it reads, it writes joints: it has no way to say no. "Don't push the
red cube" is read as ``push red ...`` and executed. So, not in the paper, a free
instruction is checked before the robot acts on it, from what the model
understood of it and from the scene (the two cubes on the table):

- its words as the model's language reads them: the text after the encoder's word
  lookup (:mod:`pgae_lite.freeform.word_lookup`), if it has one, and in it the phrases of the training
  lexicon (:func:`pgae_lite.freeform.phrasings.slot_meanings`): the actions, colours and
  speeds it names;
- the model's own readback (``repeat language``): the description it took the text to mean.

The text is first read as typed (:func:`~pgae_lite.world.typed.normalise_typed`: curly apostrophes,
zero-width and fullwidth characters); idioms of time ("right away") and a clause that sets a cube aside
("never mind the blue one, ...") are left out. Refused, with the reason in one sentence (:class:`CannotDo`)::

    too long        more than MOST_CHARACTERS characters (the encoder would read only their start)
    negation        a negator (not, never, n't, no, stop, avoid, ...) whose clause goes on
                    to name an action or a cube ("don't push the red cube"; a negated manner,
                    "no rush", is only left out; "can't you ...?", "don't forget to ..." ask for the act)
    negated speed   a speed negated, and no other named ("please not be slow and push ...")
    more than one   two actions (by their verbs), two cubes or two speeds named, a word over several
                    cubes ("both", "every", "the cubes"), a repetition ("twice", "two pushes"), two
                    opposite ways ("forward and back", "left and right"), or two sentences or steps
                    ("..., then ...") that each name an action
    outside colour  a colour word (WordNet: a kind of colour) read as none of the world's six
    outside action  no action of the world named at all (the verbs it names, if any, are said); or an
                    action read only by the word lookup from a word of no action of the world
                    (``lift`` -> ``haul``) with no direction of that action beside it
    absent cube     a colour named, or the readback's colour, that is not on the table

The closed classes of words are English grammar, written for this purpose
(:mod:`pgae_lite.freeform.refusal_words`); the rule reads the lexicon, WordNet and the scene,
never a test sentence. What the world can do is the phrase lexicon's (``LEXICON``: its actions'
verbs and directions), whatever a model's training held of it.
"""
from __future__ import annotations

import itertools
import re
from dataclasses import replace
from functools import lru_cache

from pgae_lite.freeform.phrase_lexicon import LEXICON, MEANINGS, PhraseLexicon, training_lexicon, words_of
from pgae_lite.freeform.phrasings import phrasings, slot_meanings
from pgae_lite.freeform.refusal_words import (
    MOST_CHARACTERS,
    NEGATORS,
    SEQUENCERS,
    direction_table,
    directions,
    dismissed,
    is_negator,
    opposite_ways,
    quantified,
    repetition,
    without_idioms,
)
from pgae_lite.freeform.word_lookup import WordLookup, base_forms, wordnet
from pgae_lite.util.checks import instance_of
from pgae_lite.util.errors import ArgumentError, ArgumentTypeError
from pgae_lite.world.patterns import Pattern
from pgae_lite.world.typed import normalise_typed
from pgae_lite.world.words import COLOURS, LanguageError, parse_description

# A clause ends at punctuation or at a word that joins clauses.
_CLAUSE_END = re.compile(r"[,.;:!?]|\b(?:and|but|or|then|while|before|after)\b", re.IGNORECASE)
# A sentence or step ends at a full stop or semicolon, or where a sequencing word begins the next.
_STEP_END = re.compile(r"[.;!?]|\b(?:" + "|".join(sorted(SEQUENCERS)) + r"|after that)\b", re.IGNORECASE)
#: What the robot can do, as its refusals say it (the field ``actions`` of two messages).
ACTIONS_SAID = "push (move up), pull (move down) or slide (move sideways) one cube"
#: Every sentence of :func:`refusal` and :func:`disagreement`, as templates: ``str.format`` with named fields
#: only, each filled with text already written (a repr where the sentence quotes). The page fills the same ones;
#: a template that starts with a space or a comma is a part that another one's field takes, or leaves empty.
MESSAGES: dict[str, str] = {
    "scene": "the cubes here are {left} (left) and {right} (right)",
    "negation": "I can't do {text}: it says what not to do ({negation}); tell me what to do, "
                "e.g. 'push the {colour} cube slowly'",
    "one_at_a_time": "one instruction at a time: {text} asks for {several}; tell me one action on one cube",
    "several_actions": "{count} actions ({named})",
    "several_cubes": "{count} cubes ({named})",
    "several_speeds": "{count} speeds ({named})",
    "several_steps": "{count} steps",
    "several_cubes_said": "more than one cube ({word})",
    "repeated": "the act more than once ({words})",
    "opposite_ways": "two opposite ways ({named})",
    "negated_speed": "I can't do {text}: it says what speed not to use ({negation}); tell me the speed, "
                     "e.g. 'push the {colour} cube {speed}'",
    "too_long": "an instruction of {count} characters is too long: I read at most {most}; tell me one "
                "action on one cube, e.g. 'push the {colour} cube'",
    "no_such_colour": "I know no {word} cube: the cubes of this world are {colours} or {last}{and_scene}",
    "and_scene": ", and {scene}",
    "cannot_verb": "I can't '{verb}' a cube: I can {actions}",
    "cannot_do": "I can't do {text}: I can {actions}",
    "absent_cube": "there is no {colour} cube here{as_read}: {scene}",
    "as_read": " (I read '{word}' as {colour})",
    "understood_absent": "I understood {understood}, but there is no {colour} cube here: {scene}",
    "chosen_episode": "the chosen episode is {chosen}: the verdict is against the chosen episode",
    "no_readback": "I could not say the text back as a description ({words}); {chosen}",
    "asks_otherwise": "the text asks for {asked}, as I understood it, but {chosen}",
}


class CannotDo(LanguageError):
    """A free instruction the robot will not act on; the message says why and what it can do."""


def lookup_of(encoder) -> WordLookup:
    """The lookup that reads a text's words for ``encoder``: its own, or one that knows the training words."""
    own = encoder.word_lookup
    return _words_only() if own is None else own


@lru_cache(maxsize=1)
def _words_only() -> WordLookup:
    """A lookup that knows the training lexicon and its grammar's words (20 sentences of each meaning)."""
    sentences = [t for meaning in itertools.product(*MEANINGS.values()) for t in phrasings(*meaning, 20)]
    return WordLookup(training_lexicon(), sentences)


def _reading(encoder, text: str) -> tuple[WordLookup, str, dict[str, str]]:
    """(a lookup that knows the training words, the text as the encoder reads it, the words it replaced).

    An encoder with its own word lookup reads the text through it; one without reads it as it is.
    """
    own = encoder.word_lookup
    if own is None:
        return _words_only(), text, {}
    return own, own.rewrite(text), own.replacements(text)


@lru_cache(maxsize=1)
def _colour_kinds() -> frozenset:
    """WordNet's colour sense and every sense below it (its hyponyms, all the way down)."""
    colour = wordnet().synset("color.n.01")
    return frozenset({colour, *colour.closure(lambda x: x.hyponyms())})


def is_colour_word(word: str) -> bool:
    """Whether WordNet lists ``word`` as a kind of colour (``black``, ``orange``), by any sense."""
    return any(s in _colour_kinds() for s in wordnet().synsets(word))


def _set_aside(read: str, lexicon: PhraseLexicon) -> tuple[str, list[str]]:
    """(``read`` with each clause that sets a cube aside blanked, the dismissals that name an action).

    "never mind the blue one, push the red cube" -> " , push the red cube"; a dismissal of an action
    ("forget pushing the red cube") is a negation of it."""
    kept, acted, at = [], [], 0
    ends = [m.span() for m in _CLAUSE_END.finditer(read)] + [(len(read), len(read))]
    for start, end in ends:
        clause = read[at:start]
        if dismissed(clause) and slot_meanings(clause, lexicon)["action"]:
            acted.append(" ".join(words_of(clause)))
        kept.append(" " * len(clause) if dismissed(clause) else clause)
        kept.append(read[start:end])
        at = end
    return "".join(kept), acted


def _negated(read: str, lexicon: PhraseLexicon) -> tuple[list[str], list[str]]:
    """(the negations that name an action or a cube, the speeds negated) of the text ``read``."""
    refused, speeds = [], []
    for clause in _CLAUSE_END.split(read):
        words = words_of(clause)
        at = next((i for i in range(len(words)) if is_negator(words, i)), None)
        if at is None:
            continue
        scope = slot_meanings(" ".join(words[at + 1:]), lexicon)
        if scope["action"] or scope["colour"]:
            refused.append(" ".join(words[at:]))
        speeds += [(s, " ".join(words[at:])) for s in scope["speed"]]
    return refused, speeds


def _scene_text(scene: tuple[str, str]) -> str:
    return MESSAGES["scene"].format(left=scene[0], right=scene[1])


def _more_than_one(read: str, said: dict, lexicon: PhraseLexicon, negated_speeds: list[str]) -> str | None:
    """What makes ``read`` (its phrases ``said``) more than one instruction ("2 actions (push, pull)"), or None."""
    # Actions are counted by their verbs: a direction word may be a manner ("drag it right away").
    by_verbs = slot_meanings(read, replace(lexicon, directions={a: () for a in lexicon.directions}))["action"]
    speeds = [s for s in said["speed"] if s not in negated_speeds]
    for key, named in (("several_actions", by_verbs), ("several_cubes", said["colour"]), ("several_speeds", speeds)):
        if len(set(named)) > 1:
            return MESSAGES[key].format(count=str(len(set(named))), named=", ".join(dict.fromkeys(named)))
    word, again = quantified(read), repetition(read)
    if word:
        return MESSAGES["several_cubes_said"].format(word=repr(word))
    if again:
        return MESSAGES["repeated"].format(words=repr(again))
    ways = opposite_ways(read, direction_table(lexicon))
    if ways:
        return MESSAGES["opposite_ways"].format(named=", ".join(map(repr, ways)))
    steps = [step for step in _STEP_END.split(read) if slot_meanings(step, lexicon)["action"]]
    return MESSAGES["several_steps"].format(count=str(len(steps))) if len(steps) > 1 else None


@lru_cache(maxsize=1)
def _world_action_words() -> frozenset:
    """Every word of the full lexicon's action phrases: what the world can do, in words (``LEXICON``)."""
    phrases = [p for ps in LEXICON.phrases("action").values() for p in ps] + list(LEXICON.neutral)
    return frozenset(w for p in phrases for w in words_of(p))


def looked_up_action(word: str, replacement: str, lexicon: PhraseLexicon) -> list[str]:
    """The actions the lookup reads into ``word`` (its ``replacement``'s), where ``word`` is no word of the
    world's actions (nor a form of one): ``lift`` -> ``haul``: [pull]; else []."""
    acts = slot_meanings(replacement, lexicon)["action"]
    return [] if not acts or base_forms(word.lower()) & _world_action_words() else acts


def _outside_the_world(text: str, read: str, said: dict, lookup: WordLookup, swapped: dict[str, str],
                       scene: tuple[str, str] | None) -> str | None:
    """A colour or an action the world does not have, said as what the robot can do; or None."""
    outside = [w for w in dict.fromkeys(words_of(text)) if w not in swapped and not lookup.is_known(w)
               and w not in COLOURS and re.fullmatch(r"[a-z]{3,}", w) and is_colour_word(w)]
    if outside:
        and_scene = MESSAGES["and_scene"].format(scene=_scene_text(scene)) if scene else ""
        return MESSAGES["no_such_colour"].format(word=outside[0], colours=", ".join(COLOURS[:-1]), last=COLOURS[-1],
                                                 and_scene=and_scene)
    if not said["action"]:
        verbs = [w for w in dict.fromkeys(words_of(text)) if not lookup.is_known(w) and wordnet().synsets(w, pos="v")]
        if verbs:
            return MESSAGES["cannot_verb"].format(verb=verbs[0], actions=ACTIONS_SAID)
        return MESSAGES["cannot_do"].format(text=repr(text.strip()), actions=ACTIONS_SAID)
    ways = {meaning for _, _, meaning, _ in directions(read, direction_table(lookup.lexicon))}
    for word, replacement in swapped.items():               # the person's own word, judged as well
        acts = looked_up_action(word, replacement, lookup.lexicon)
        if acts and not set(acts) & ways:
            return MESSAGES["cannot_verb"].format(verb=word.lower(), actions=ACTIONS_SAID)
    return None


def _absent_cube(said: dict, lexicon: PhraseLexicon, swapped: dict[str, str], scene: tuple[str, str],
                 understood: str | None) -> str | None:
    """A cube named, or understood (the readback's colour, whether or not the words name one), that is not
    on the table; or None."""
    for colour in dict.fromkeys(said["colour"]):
        if colour not in scene:
            word = next((w for w, v in swapped.items() if colour in slot_meanings(v, lexicon)["colour"]), None)
            as_read = MESSAGES["as_read"].format(word=word, colour=colour) if word else ""
            return MESSAGES["absent_cube"].format(colour=colour, as_read=as_read, scene=_scene_text(scene))
    if understood is None:
        return None
    try:                                                  # the colour the model said back
        colour = parse_description(understood)[1]
    except LanguageError:
        return None
    return None if colour in scene else \
        MESSAGES["understood_absent"].format(understood=repr(understood), colour=colour, scene=_scene_text(scene))


def _checked(text, encoder, scene, understood) -> tuple[str, tuple[str, str] | None]:
    """(``text`` as typed, in its plain form; ``scene`` as a pair), or a clear error for a wrong argument."""
    text = normalise_typed(instance_of("text", text, str, "the instruction as typed (a string)"))
    if not hasattr(encoder, "word_lookup"):
        raise ArgumentTypeError(f"encoder must be a model's language encoder (with a word_lookup, None for "
                                f"none); got {type(encoder).__name__}")
    instance_of("understood", understood, str, "the model's readback (a string)", optional=True)
    if scene is not None:
        if not isinstance(scene, (tuple, list)) or len(scene) != 2 or not all(isinstance(c, str) for c in scene):
            raise ArgumentError(f"scene must be the colours of the (left, right) cubes, a pair such as "
                                f"('red', 'blue'), or None; got {type(scene).__name__} {scene!r:.80}")
        scene = (scene[0], scene[1])
    return text, scene


def refusal(text: str, encoder, scene: tuple[str, str] | None = None, understood: str | None = None) -> str | None:
    """Why the robot will not act on the free instruction ``text``, or None: it may.

    ``encoder``: the model's language encoder (its word lookup, if it has one, reads the words);
    ``scene``: the colours of the (left, right) cubes on the table, if known; ``understood``: the
    model's readback of the text (``repeat language``), if known.
    """
    text, scene = _checked(text, encoder, scene, understood)
    example = scene[0] if scene else COLOURS[0]
    if len(text) > MOST_CHARACTERS:
        return MESSAGES["too_long"].format(count=str(len(text)), most=str(MOST_CHARACTERS), colour=example)
    lookup, read, swapped = _reading(encoder, text)
    read, dismissals = _set_aside(without_idioms(read), lookup.lexicon)   # "right away", "never mind X, ..." out
    negations, negated = _negated(read, lookup.lexicon)
    negations = dismissals + negations
    if negations:
        return MESSAGES["negation"].format(text=repr(text.strip()), negation=repr(negations[0]), colour=example)
    said = slot_meanings(read, lookup.lexicon)                         # the actions, cubes and speeds it names
    negated_speeds = [s for s, _ in negated]
    if negated and not [s for s in said["speed"] if s not in negated_speeds]:
        other = [s for s in MEANINGS["speed"] if s not in negated_speeds]
        return MESSAGES["negated_speed"].format(
            text=repr(text.strip()), negation=repr(negated[0][1]), colour=example, speed=(other or ["slowly"])[0])
    several = _more_than_one(read, said, lookup.lexicon, negated_speeds)
    if several:
        return MESSAGES["one_at_a_time"].format(text=repr(text.strip()), several=several)
    outside = _outside_the_world(text, read, said, lookup, swapped, scene)
    if outside:
        return outside
    return None if scene is None else _absent_cube(said, lookup.lexicon, swapped, scene, understood)


def disagreement(understood: str | None, pattern: int) -> str | None:
    """A sentence saying that the model's readback of a text and the episode ``pattern`` disagree, or None."""
    p = Pattern.from_number(pattern)
    chosen = MESSAGES["chosen_episode"].format(chosen=f"{p.action} {p.colour} {p.speed}")
    try:
        meaning = parse_description(understood or "")
    except LanguageError:
        return MESSAGES["no_readback"].format(words=repr(understood or "<EOS>"), chosen=chosen)
    if meaning != (p.action, p.colour, p.speed):
        return MESSAGES["asks_otherwise"].format(asked=" ".join(meaning), chosen=chosen)
    return None


def check_instruction(text: str, encoder, scene: tuple[str, str] | None = None,
                      understood: str | None = None) -> None:
    """Raise :class:`CannotDo` with :func:`refusal`'s reason if the robot will not act on ``text``."""
    reason = refusal(text, encoder, scene, understood)
    if reason:
        raise CannotDo(reason)


__all__ = ["ACTIONS_SAID", "MESSAGES", "NEGATORS", "SEQUENCERS", "CannotDo", "check_instruction", "disagreement",
           "looked_up_action", "refusal"]
