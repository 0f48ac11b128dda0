"""Many ways to say one instruction: training-time language augmentation for PGAE-BERT.

Paper, Sec. 3 ("Language Autoencoder", last paragraph): PGAE-BERT reads its
input with a pretrained BERT, so it "has the potential to recognise unseen
natural language". Trained only on the dataset's three-word descriptions
(``push red slowly`` and its synonyms, :mod:`pgae_lite.world.words`), the frozen
encoder's sentence vectors of free-form instructions land far from those it
was trained on. Not from the paper: this module says each instruction in many
ways for training, from a grammar and a lexicon written for the purpose, not
from any test sentence (the held-out ones are in :mod:`pgae_lite.freeform.paraphrases`).

A sentence is a carrier (``NICO, ...``) around a politeness frame (``could
you ...?``) around a clause in one of several word orders; the clause names
the action (a verb, with an optional direction that matches it, or a plain
verb such as ``move`` with a direction it then needs), the cube (determiner,
colour, noun) and the speed (an adverb or phrase, before the verb, at the end,
fronted, or an adjective). The words are in :mod:`pgae_lite.freeform.phrase_lexicon`
(:data:`~pgae_lite.freeform.phrase_lexicon.LEXICON`);
:meth:`~pgae_lite.freeform.phrase_lexicon.PhraseLexicon.without` holds words out, to
measure sentences with words never seen in training. :func:`phrasings` gives n
distinct sentences, the same for the same seed; :func:`slot_meanings` finds
the lexicon's phrases in a text.
"""
from __future__ import annotations

import itertools
import random
import re

from pgae_lite.freeform.phrase_lexicon import LEXICON, MEANINGS, SLOTS, PhraseLexicon, words_of
from pgae_lite.util.checks import instance_of, whole_number
from pgae_lite.util.errors import ArgumentError
from pgae_lite.util.storage import config_digest

#: Verbs that double their last letter before -ing (``drag`` -> ``dragging``).
_DOUBLED = ("drag", "get", "prod", "propel", "skid", "slip", "tug")
_MANNERS = ("way", "manner", "motion", "movement")


def gerund(verb: str) -> str:
    """The -ing form of a verb: ``push`` -> ``pushing``, ``slide`` -> ``sliding``."""
    if verb in _DOUBLED:
        return verb + verb[-1] + "ing"
    stem = verb[:-1] if verb.endswith("e") and not verb.endswith("ee") else verb
    return stem + "ing"


def _check_meaning(action: str, colour: str, speed: str) -> None:
    for slot, value in zip(SLOTS, (action, colour, speed)):
        if value not in MEANINGS[slot]:
            raise ArgumentError(f"{slot} {value!r} is not one of: "
                                f"{', '.join(MEANINGS[slot])}")


def _action(lex: PhraseLexicon, action: str, rng: random.Random) -> tuple[str, str]:
    """A verb and a direction (maybe ``""``) that together say ``action``."""
    directions = lex.directions.get(action, ())
    kinds = [(verbs, weight, needs) for verbs, weight, needs in (
        (lex.verbs.get(action, ()), 0.6, False),
        (lex.steered.get(action, ()), 0.15, True),
        (lex.neutral, 0.25, True)) if verbs and (directions or not needs)]
    if not kinds:
        raise ArgumentError(f"the lexicon has no verb for the action {action!r} "
                            "(too many words held out)")
    verbs, _, needs = rng.choices(kinds, [weight for _, weight, _ in kinds])[0]
    wants = directions and (needs or rng.random() < 0.4)
    return rng.choice(verbs), rng.choice(directions) if wants else ""


def _object(lex: PhraseLexicon, colour: str, rng: random.Random) -> str:
    """The cube: ``the red cube``, ``that block which is crimson``, ``the lime one``."""
    det, noun, name = (rng.choice(lex.determiners), rng.choice(lex.nouns),
                       rng.choice(lex.colours[colour]))
    size = rng.choice(lex.sizes) + " " if lex.sizes and rng.random() < 0.2 else ""
    return rng.choice((f"{det} {size}{name} {noun}",) * 4 + (
        f"{det} {size}{noun} that is {name}", f"{det} {noun} which is {name}",
        f"{det} {name} one", f"{det} {name}-coloured {noun}",
        f"{det} {name} coloured {noun}", f"{det} {noun} in {name}"))


def _clause(lex: PhraseLexicon, action: str, obj: str, direction: str, speed: str,
            rng: random.Random, fronted: bool) -> tuple[str, str]:
    """A word order: the clause with ``{}`` for its verb, and its own verb (or ``""``).

    ``speed`` is the speed's meaning; with ``fronted`` the clause leaves it out.
    """
    adverb, d = "" if fronted else rng.choice(lex.speeds[speed]), direction
    options = [(f"{{}} {obj} {d} {adverb}", "")] * 3
    if d and re.fullmatch(r"[a-z]+", adverb):
        options.append((f"{{}} {obj} {adverb} {d}", ""))
    if d in lex.particles:
        options.append((f"{{}} {d} {obj} {adverb}", ""))
    if re.fullmatch(r"[a-z]+ly", adverb):
        options += [(f"{adverb} {{}} {obj} {d}", "")] * 2
    if adverb:
        options.append((f"{{}} {obj} {d} and do it {adverb}", ""))
    if not fronted and lex.adjectives.get(speed):
        adj = rng.choice(lex.adjectives[speed])
        options += [(f"{{}} {obj} {d} and make it {adj}", ""),
                    (f"{{}} {obj} {d} in a {adj} {rng.choice(_MANNERS)}", "")]
        options += [(f"{{}} {obj} a {adj} {m} {d}", "give")
                    for m in lex.motions.get(action, ())[:1] if rng.random() < 0.5]
    return rng.choice(options)


def phrasing(action: str, colour: str, speed: str, rng: random.Random,
             lexicon: PhraseLexicon | None = None) -> str:
    """One random sentence that tells NICO to do (action, colour, speed).

    ``rng`` is a ``random.Random``; ``lexicon`` (a
    :class:`~pgae_lite.freeform.phrase_lexicon.PhraseLexicon`) defaults to
    :data:`~pgae_lite.freeform.phrase_lexicon.LEXICON`.
    """
    _check_meaning(action, colour, speed)
    instance_of("rng", rng, random.Random, "a random.Random")
    lex = instance_of("lexicon", lexicon, PhraseLexicon, "a PhraseLexicon",
                      optional=True) or LEXICON
    for slot, value in (("colour", colour), ("speed", speed)):
        if not lex.phrases(slot)[value]:
            raise ArgumentError(f"the lexicon has no word for the {slot} {value!r} "
                                "(too many words held out)")
    verb, direction = _action(lex, action, rng)
    obj = _object(lex, colour, rng)
    fronted = rng.random() < 0.12
    clause, own_verb = _clause(lex, action, obj, direction, speed, rng, fronted)
    verb = own_verb or verb
    if not fronted and rng.random() < 0.12:      # the cube named first, then "it"
        lead = rng.choice(("find {}, and", "see {}?", "{}:", "look at {}, then",
                           "there is {};", "spot {} and"))
        text = lead.format(obj) + " " + clause.replace(obj, "it").format(verb)
    elif lex.gerund_frames and " and " not in clause and rng.random() < 0.1:
        text = rng.choice(lex.gerund_frames).format(clause.format(gerund(verb)))
    else:
        text = rng.choice(lex.frames or ("{}",)).format(clause.format(verb))
    if fronted:
        text = rng.choice(lex.speeds[speed]) + ", " + text
    question = text.endswith("?")
    text = rng.choice(lex.carriers or ("{}",)).format(text.rstrip("?"))
    text = re.sub(r"\s+([,;:?])", r"\1", re.sub(r"\s+", " ", text)).strip()
    end = "?" if question else rng.choice(("", ".", ".", "!"))
    return text[0].upper() + text[1:] + end


def phrasings(action: str, colour: str, speed: str, n: int, seed: int = 0,
              lexicon: PhraseLexicon | None = None) -> list[str]:
    """``n`` distinct sentences for one meaning; the same seed gives the same list.

    Each meaning has its own random stream, seeded by ``seed`` and the meaning.
    """
    _check_meaning(action, colour, speed)
    n = whole_number("n", n, 1)
    seed = whole_number("seed", seed, 0)
    rng = random.Random(f"{seed} {action} {colour} {speed}")
    found: dict[str, None] = {}
    for _ in range(20 * n):
        found[phrasing(action, colour, speed, rng, lexicon)] = None
        if len(found) == n:
            return list(found)
    raise ArgumentError(f"n={n} is more than the {len(found)} distinct sentences "
                        f"the lexicon gave for {action} {colour} {speed}")


def phrasings_digest(n: int, seed: int = 0, lexicon: PhraseLexicon | None = None) -> str:
    """12 hex digits naming the ``n`` sentences :func:`phrasings` gives every meaning.

    Part of the cache name of a model trained on phrasings: an edited lexicon or
    grammar gives other sentences, so the model is trained again, never reused.
    """
    return config_digest([phrasings(*meaning, n, seed=seed, lexicon=lexicon)
                          for meaning in itertools.product(*MEANINGS.values())])


def phrase_table(lexicon: PhraseLexicon | None = None) -> dict[tuple[str, ...], tuple[str, str] | None]:
    """The phrases :func:`slot_meanings` reads: each phrase's words -> (slot, meaning), or None for the
    frame and carrier words it skips."""
    lex = lexicon or LEXICON
    table: dict[tuple[str, ...], tuple[str, str] | None] = {
        tuple(words_of(piece)): None for frame in (*lex.frames, *lex.gerund_frames,
                                                 *lex.carriers)
        for piece in frame.split("{}")}
    for slot in SLOTS:
        for meaning, phrases in lex.phrases(slot).items():
            table.update({tuple(words_of(p)): (slot, meaning) for p in phrases})
    for action in MEANINGS["action"]:            # the -ing forms of the gerund frames
        table.update({(gerund(v),): ("action", action)
                      for v in (*lex.verbs.get(action, ()), *lex.steered.get(action, ()))})
    return table


def slot_meanings(text: str, lexicon: PhraseLexicon | None = None
                  ) -> dict[str, list[str]]:
    """The meaning of each slot phrase in ``text``, by slot; longest phrases first.

    Reads the lexicon's phrases only (a word it lacks says nothing); frame and
    carrier words are skipped, so ``go ahead and`` is not the direction ``ahead``.
    """
    table = phrase_table(lexicon)
    longest = max(map(len, table))
    words, found, i = words_of(text), {slot: [] for slot in SLOTS}, 0
    while i < len(words):
        for k in range(min(longest, len(words) - i), 0, -1):
            if tuple(words[i:i + k]) in table:
                hit = table[tuple(words[i:i + k])]
                if hit:
                    found[hit[0]].append(hit[1])
                i += k
                break
        else:
            i += 1
    return found


__all__ = ["gerund", "phrase_table", "phrasing", "phrasings", "phrasings_digest", "slot_meanings"]
