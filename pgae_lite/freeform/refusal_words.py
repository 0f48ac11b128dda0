"""The refusal rule's closed classes of English words, and what it finds with them in a text (not in the paper).

Paper, Sec. 3: PGAE-BERT reads any text and always acts; :mod:`pgae_lite.freeform.refusals` (not in the
paper) decides first whether the robot acts. This module holds the English grammar that rule reads
beside the phrase lexicon: which words negate, which negations still ask for the act, which clauses set a
cube aside, and which words ask for more than one cube, more than one act, or two opposite ways::

    negation         a negator (not, never, n't, ...) before an action or a cube: "don't push the red cube"
      but a request  an inverted negative auxiliary, "can't you push ...?", "won't you ...", "why don't you ..."
      but a double   a negator before a verb of leaving undone: "don't forget to push", "do not hesitate to ..."
    set aside        a clause that opens with a dismissal and names a cube but no action:
                     "never mind the blue one, push the red cube", "forget the blue cube, pull the red one"
    quantifier       a word over several cubes: every, each, both, all/either/any before a cube (or "them
                     all"), a plural cube noun ("the two cubes"), "them"
    repetition       twice, thrice, repeatedly, "again and again", "back and forth", a count before "times"
                     or before an action's plural noun ("three times", "two pushes")
    idioms           "right away", "straight away": words of time, not the way "away" (left out first)
    opposite ways    two directions of different actions, or the two sides, joined only by and/or/then/to:
                     "forward and back", "left and right", "up or down"

The classes are English grammar, written for this purpose; the nouns and actions are the phrase lexicon's.
The page reads the same classes (:func:`closed_classes`, written by :mod:`pgae_lite.web.refusal_data`).
"""
from __future__ import annotations

import re
from functools import lru_cache

from pgae_lite.freeform.phrase_lexicon import LEXICON, PhraseLexicon

#: Words that negate what follows them in their clause (and any word ending in n't).
NEGATORS = frozenset("not never no nor neither nothing nobody stop avoid refrain dont cannot".split())
#: Words that start a further step of a sequence.
SEQUENCERS = frozenset("then afterwards afterward later next finally also".split())
#: Negative auxiliaries that, before "you" or "we", ask a question that is a request ("can't you push ...?").
INVERTED = frozenset("can't couldn't won't wouldn't shouldn't".split())
#: The words after such an auxiliary that make it a question.
ASKED = frozenset("you we".split())
#: Verbs of leaving a thing undone: negated, they ask for it ("don't forget to push", "never fail to ...").
OMISSIONS = frozenset("forget fail neglect omit hesitate delay".split())
#: Words that may stand between a negator and what it negates ("don't you ever forget to ...").
FILLERS = frozenset("you ever please just".split())
#: Phrases that set aside what their clause names ("never mind the blue one, ..."), as word tuples.
DISMISSALS = ("never mind", "nevermind", "forget about", "forget", "ignore", "disregard", "leave")
#: Words that may open a clause before its dismissal ("oh, never mind ...", "ok forget the blue one").
OPENERS = frozenset("oh ok okay well actually so and but please just".split())
#: Words over several things; the first three always, the others before a cube (or after "them").
QUANTIFIERS = ("every", "each", "both", "all", "either", "any")
ALWAYS_QUANTIFIED = frozenset(QUANTIFIERS[:3])
#: Plural pronouns that stand for several cubes.
PLURAL_PRONOUNS = frozenset(("them",))
#: Words that ask for an act more than once, and phrases of them (word tuples).
REPETITIONS = frozenset("twice thrice repeatedly".split())
REPEATED_PHRASES = ("again and again", "over and over", "back and forth", "to and fro", "side to side",
                    "round and round", "time after time", "more than once", "time and again")
#: Counts of more than one (and any number but 0 and 1, written in digits), before "times" or an action's noun.
COUNTS = frozenset("two three four five six seven eight nine ten eleven twelve twenty hundred several many "
                   "multiple few couple dozen numerous".split())
#: The sides of the table, a direction of their own.
SIDES = ("left", "right")
#: Words after "right" that make it no side: "right away", "right now".
NOT_A_SIDE_AFTER = frozenset("away now then here there off ahead".split())
#: Words that may join two directions into one request for both ("forward and back", "left or right").
JOINERS = frozenset("and or then to the nor".split())
#: Idioms of time whose words are no direction nor side: "push it right away" asks for no way "away".
IDIOMS = ("right away", "straight away", "right now")
#: The idioms as one pattern (the page applies the same).
IDIOM_PATTERN = r"\b(?:" + "|".join(i.replace(" ", r"\s+") for i in IDIOMS) + r")\b"
#: The most characters one typed instruction may have (the encoder reads a few hundred words at most).
MOST_CHARACTERS = 1000

_TOKEN = re.compile(r"[a-z']+|[0-9]+")


def without_idioms(text: str) -> str:
    """``text`` with its idioms of time blanked (as many spaces): "push it right away" -> "push it           "."""
    return re.sub(IDIOM_PATTERN, lambda m: " " * len(m.group(0)), text, flags=re.IGNORECASE)


def tokens(text: str) -> list[str]:
    """Lower-case words and numbers of ``text`` (``words_of`` with the digits kept)."""
    return _TOKEN.findall(text.lower())


def plural(noun: str) -> str:
    """An English noun's plural: box -> boxes, cube -> cubes."""
    return noun + ("es" if re.search(r"(s|x|z|ch|sh)$", noun) else "s")


@lru_cache(maxsize=1)
def cube_nouns() -> tuple[frozenset, frozenset]:
    """(the lexicon's cube nouns and "one", their plurals and "ones"): the last word of each noun phrase."""
    singular = {noun.split()[-1] for noun in LEXICON.nouns} | {"one"}
    return frozenset(singular), frozenset({plural(n) for n in singular} | {"ones"})


@lru_cache(maxsize=1)
def action_plurals() -> frozenset:
    """The plural nouns of the lexicon's one-word action verbs and motions: pushes, pulls, shoves, ..."""
    words = {p for a in LEXICON.verbs for p in (*LEXICON.verbs[a], *LEXICON.motions[a]) if " " not in p}
    return frozenset(plural(w) for w in words) | {"times"}


def closed_classes() -> dict:
    """Every class above, as lists the page reads (``refusals.json``)."""
    singular, plurals = cube_nouns()
    return {"negators": sorted(NEGATORS), "sequencers": sorted(SEQUENCERS), "inverted": sorted(INVERTED),
            "asked": sorted(ASKED), "omissions": sorted(OMISSIONS), "fillers": sorted(FILLERS),
            "dismissals": list(DISMISSALS), "openers": sorted(OPENERS), "quantifiers": list(QUANTIFIERS),
            "always_quantified": sorted(ALWAYS_QUANTIFIED), "plural_pronouns": sorted(PLURAL_PRONOUNS),
            "repetitions": sorted(REPETITIONS), "repeated_phrases": list(REPEATED_PHRASES),
            "counts": sorted(COUNTS), "sides": list(SIDES), "not_a_side_after": sorted(NOT_A_SIDE_AFTER),
            "joiners": sorted(JOINERS), "idioms": IDIOM_PATTERN, "most_characters": MOST_CHARACTERS,
            "cube_nouns": sorted(singular), "cube_plurals": sorted(plurals), "action_plurals": sorted(action_plurals())}


def is_negator(words: list[str], i: int) -> bool:
    """Whether ``words[i]`` negates what follows it: a negator that is not a request nor a double negation."""
    word = words[i]
    if word not in NEGATORS and not word.endswith("n't"):
        return False
    after = words[i + 1] if i + 1 < len(words) else ""
    if (word in INVERTED and after in ASKED) or (i > 0 and words[i - 1] == "why"):
        return False                                             # "can't you ...?", "why don't you ...", "why not"
    k = i + 1
    while k < len(words) and words[k] in FILLERS:
        k += 1
    return not (k < len(words) and words[k] in OMISSIONS)         # "don't forget to ...": asks for it


def dismissed(clause: str) -> bool:
    """Whether ``clause`` opens with a dismissal ("never mind the blue one", "ok, forget the blue cube")."""
    words = tokens(clause)
    k = 0
    while k < len(words) and words[k] in OPENERS:
        k += 1
    return any(words[k:k + len(d.split())] == d.split() for d in DISMISSALS)


def quantified(text: str) -> str | None:
    """The word of ``text`` that asks for several cubes ("every", "both", "cubes", "them"), or None."""
    words = tokens(text)
    singular, plurals = cube_nouns()
    for i, word in enumerate(words):
        if word in ALWAYS_QUANTIFIED or word in plurals or word in PLURAL_PRONOUNS:
            return word
        if word in QUANTIFIERS:
            ahead = words[i + 1:i + 4]
            if any(w in singular or w in plurals or w in ("of", "them") for w in ahead) or \
                    (i > 0 and words[i - 1] in PLURAL_PRONOUNS) or i == len(words) - 1:
                return word
    return None


def repetition(text: str) -> str | None:
    """The words of ``text`` that ask for the act more than once ("twice", "three times"), or None."""
    words, units = tokens(text), action_plurals()
    joined = f" {' '.join(words)} "
    for phrase in REPEATED_PHRASES:
        if f" {phrase} " in joined:
            return phrase
    for i, word in enumerate(words):
        if word in REPETITIONS:
            return word
        if word in COUNTS or (word.isdigit() and int(word) > 1):
            for k in range(i + 1, min(i + 4, len(words))):         # up to two words between: "two quick pushes"
                if words[k] in units:
                    return " ".join(words[i:k + 1])
    return None


def direction_table(lexicon: PhraseLexicon) -> dict[str, str]:
    """Each direction phrase of ``lexicon`` (its words, single spaces) -> its action."""
    return {" ".join(tokens(p)): action for action, phrases in lexicon.directions.items() for p in phrases}


def directions(text: str, table: dict[str, str]) -> list[tuple[int, int, str, str]]:
    """The directions ``text`` names, longest phrases first: (first word, end, meaning, words); a side of the
    table ("left", "right", not "right away" nor "the left cube") is a meaning of its own."""
    words, nouns = tokens(text), cube_nouns()[0] | cube_nouns()[1]
    longest = max(len(p.split()) for p in table)
    found, i = [], 0
    while i < len(words):
        after = words[i + 1] if i + 1 < len(words) else ""
        if words[i] in SIDES and after not in nouns and not (words[i] == "right" and after in NOT_A_SIDE_AFTER):
            found.append((i, i + 1, words[i], words[i]))
            i += 1
            continue
        for k in range(min(longest, len(words) - i), 0, -1):
            piece = " ".join(words[i:i + k])
            if piece in table:
                found.append((i, i + k, table[piece], piece))
                i += k
                break
        else:
            i += 1
    return found


def opposite_ways(text: str, table: dict[str, str]) -> list[str] | None:
    """Two directions of different meanings (two actions, or both sides) that ``text`` joins into one
    request, as typed (["forward", "back"]), or None."""
    found, words = directions(text, table), tokens(text)
    for (_, end, meaning, said), (start, _, other, said_next) in zip(found, found[1:]):
        if meaning != other and all(w in JOINERS for w in words[end:start]):
            return [said, said_next]
    return None


__all__ = ["ALWAYS_QUANTIFIED", "ASKED", "COUNTS", "DISMISSALS", "FILLERS", "IDIOMS", "IDIOM_PATTERN", "INVERTED",
           "JOINERS",
           "MOST_CHARACTERS", "NEGATORS", "NOT_A_SIDE_AFTER", "OMISSIONS", "OPENERS", "PLURAL_PRONOUNS",
           "QUANTIFIERS", "REPEATED_PHRASES", "REPETITIONS", "SEQUENCERS", "SIDES", "action_plurals",
           "closed_classes", "cube_nouns", "direction_table", "directions", "dismissed", "is_negator",
           "opposite_ways", "plural", "quantified", "repetition", "tokens", "without_idioms"]
