"""What the robot refuses, as data for the reader's browser (not in the paper).

Paper, Sec. 3: PGAE-BERT reads any text and always acts. :mod:`pgae_lite.freeform.refusals` decides
first whether the robot acts on a free instruction, from its words, the model's readback and the
scene, reading the phrase lexicon and WordNet. The page has neither, so the build writes what the
rule reads, and ``book/_js/pgae-refusals.js`` applies the same rule to it. What the robot says is
no part of this data: each sentence is a template of ``refusals.MESSAGES``, which the page reads from
its manifest (:mod:`pgae_lite.web.messages`) and fills as Python formats it::

    refusals.json        shared by the models:
      negators, sequencers, ..., most_characters    the rule's closed classes of words
                                                   (refusal_words.closed_classes)
      clause_end, step_end                         its patterns
      colours, speeds, actions_said                the world's six colours (the first: a negation's example),
                                                   its two speeds;
                                                   what the robot can do (the field ``actions`` of two messages)
      colour_words       WordNet's words with a sense that is a kind of colour (refusals.is_colour_word)
      verbs              WordNet's words with a verb sense, front-coded (:func:`front_coded`)
    models/NAME.refusals.json   one model's reading:
      phrases            the phrase table slot_meanings reads, [words, slot, meaning] (None: skipped)
      phrases_by_verbs   the same with the directions left out (actions counted by their verbs)
      directions         each direction phrase of its lexicon -> its action (refusal_words.direction_table)
      known              the words of ``colour_words`` and ``verbs`` its lookup knows (is_known)
      untrusted          the words of its word table read as an action that is no word of the world's
                         actions (refusals.looked_up_action: ``lift`` -> ``haul``)

The words are decided over the same candidates as the word table (:mod:`pgae_lite.web.word_table`):
each lemma of WordNet and each form one ending away; a word outside them has no sense, so Python
counts it as neither a colour nor a verb either.
"""
from __future__ import annotations

from dataclasses import replace

from pgae_lite.freeform import refusals
from pgae_lite.freeform.phrasings import phrase_table
from pgae_lite.freeform.refusal_words import closed_classes, direction_table
from pgae_lite.freeform.word_lookup import WordLookup, wordnet
from pgae_lite.web.word_table import candidates, word_table
from pgae_lite.world.words import COLOURS, SPEEDS


def front_coded(words: list[str]) -> str:
    """Sorted words as one string, each line the length of the prefix it shares with the line before
    (one character, ``chr(48 + k)``, k < 40) and the rest: ``push, pushed`` -> ``"0push\\n4ed"``."""
    lines, before = [], ""
    for word in sorted(words):
        k = 0
        while k < min(len(word), len(before), 39) and word[k] == before[k]:
            k += 1
        lines.append(chr(48 + k) + word[k:])
        before = word
    return "\n".join(lines)


def shared_words(words=None) -> dict:
    """What every model's refusal reads: the rule's words and patterns, WordNet's colour words and verbs
    (a sorted list here; :func:`front_coded` when written), decided over ``words`` (default: the word
    table's candidates, :func:`~pgae_lite.web.word_table.candidates`)."""
    dictionary = wordnet()
    words = candidates(shortest=1) if words is None else sorted(set(words))   # a verb may be short: "go"
    return {**closed_classes(), "clause_end": refusals._CLAUSE_END.pattern, "step_end": refusals._STEP_END.pattern,
            "colours": list(COLOURS), "speeds": list(SPEEDS), "actions_said": refusals.ACTIONS_SAID,
            "colour_words": [w for w in words if len(w) >= 3 and refusals.is_colour_word(w)],
            "verbs": [w for w in words if dictionary.synsets(w, pos="v")]}


def _table(lexicon) -> list:
    return [[" ".join(words), *(hit or (None, None))] for words, hit in phrase_table(lexicon).items()]


def model_reading(encoder, shared: dict, table: dict[str, str] | None = None) -> dict:
    """One model's phrase tables, its directions, the words of ``shared`` its lookup knows and the words of
    its word ``table`` (default: :func:`~pgae_lite.web.word_table.word_table` of its own lookup) read as an
    action the world has no word for."""
    lookup: WordLookup = refusals.lookup_of(encoder)
    lexicon = lookup.lexicon
    by_verbs = replace(lexicon, directions={a: () for a in lexicon.directions})
    if table is None:
        table = {} if encoder.word_lookup is None else word_table(encoder.word_lookup)
    return {"phrases": _table(lexicon), "phrases_by_verbs": _table(by_verbs),
            "directions": direction_table(lexicon),
            "known": sorted(w for w in (*shared["verbs"], *shared["colour_words"]) if lookup.is_known(w)),
            "untrusted": sorted(w for w, read in table.items() if refusals.looked_up_action(w, read, lexicon))}


__all__ = ["front_coded", "model_reading", "shared_words"]
