"""The lexicon of :mod:`pgae_lite.freeform.phrasings`: the words of each slot, by meaning.

Not from the paper (training-time language augmentation for PGAE-BERT, Sec. 3).
Written from general English for this purpose, not from any test sentence:
actions (push: away from the robot; pull: toward it; slide: to the side) as
verbs and directions, the six colours with their shades and everyday names,
the two speeds as adverbs, phrases and adjectives, the cube's nouns, and the
politeness frames and carrier sentences around an instruction. The training
synonyms of :data:`pgae_lite.world.words.SYNONYMS` are among the words (``move
up`` is the neutral verb ``move`` with the direction ``up``).
"""
from __future__ import annotations

import re
from dataclasses import dataclass, fields, replace

from pgae_lite.util.checks import instance_of
from pgae_lite.util.errors import ArgumentError
from pgae_lite.world.words import ACTIONS, COLOURS, SPEEDS, SYNONYMS, VOCABULARY, LanguageError

SLOTS = ("action", "colour", "speed")
#: The meanings each slot may say.
MEANINGS = dict(zip(SLOTS, (ACTIONS, COLOURS, SPEEDS)))


def _spaced(word: str) -> str:
    """A synonym as the encoder reads it: ``greenish-blue`` -> ``greenish blue``."""
    return SYNONYMS[word].replace("-", " ")


def _shades(name: str, *others: str) -> tuple[str, ...]:
    """A colour name, its shades (``bright red``) and other names for it."""
    shades = (f"{m} {name}" for m in ("bright", "dark", "deep", "vivid"))
    return (name, *shades, *others)


@dataclass(frozen=True)
class PhraseLexicon:
    """The words of the grammar; a dict maps each meaning to the phrases that say it.

    ``verbs`` say the action alone (a direction may follow); ``steered`` verbs
    need a direction of their meaning (``bring ... closer``); ``neutral`` verbs
    any direction (``move ... away``). ``particles`` are the directions that may
    also stand before the object (``pull back the cube``); ``motions`` are nouns
    of the action (``give it a quick push``); ``adjectives`` say the speed as an
    adjective (``make it quick``). ``frames`` hold ``{}`` for the clause, and
    ``gerund_frames`` take the clause with its verb in -ing form.
    """

    verbs: dict[str, tuple[str, ...]]
    steered: dict[str, tuple[str, ...]]
    neutral: tuple[str, ...]
    directions: dict[str, tuple[str, ...]]
    particles: tuple[str, ...]
    motions: dict[str, tuple[str, ...]]
    colours: dict[str, tuple[str, ...]]
    speeds: dict[str, tuple[str, ...]]
    adjectives: dict[str, tuple[str, ...]]
    nouns: tuple[str, ...]
    sizes: tuple[str, ...]
    determiners: tuple[str, ...]
    frames: tuple[str, ...]
    gerund_frames: tuple[str, ...]
    carriers: tuple[str, ...]

    def phrases(self, slot: str) -> dict[str, tuple[str, ...]]:
        """Every phrase of ``slot`` (action, colour or speed), by its meaning."""
        if slot not in SLOTS:
            raise ArgumentError(f"slot {slot!r} is not one of: {', '.join(SLOTS)}")
        parts = {"action": (self.verbs, self.steered, self.directions, self.motions),
                 "colour": (self.colours,),
                 "speed": (self.speeds, self.adjectives)}[slot]
        return {m: tuple(dict.fromkeys(p for part in parts for p in part.get(m, ())))
                for m in MEANINGS[slot]}

    def words(self) -> set[str]:
        """Every word of the lexicon's phrases and frames, lower case.

        A sentence may also hold a few words of the grammar itself (``that is``,
        ``and do it``, ``give ... a``), the same for every meaning.
        """
        texts = [t for f in fields(self) for t in _entries(getattr(self, f.name))]
        return {w for t in texts for w in words_of(t.replace("{}", " "))}

    def without(self, *words: str) -> "PhraseLexicon":
        """This lexicon less every phrase or frame that contains one of ``words``."""
        held = {instance_of("words", w, str, "strings").lower() for w in words}

        def keep(items: tuple[str, ...]) -> tuple[str, ...]:
            return tuple(t for t in items if not held & set(words_of(t)))
        return replace(self, **{f.name: {k: keep(v) for k, v in value.items()}
                                if isinstance(value := getattr(self, f.name), dict)
                                else keep(value) for f in fields(self)})


def held_out_words(lexicon: "PhraseLexicon | None" = None) -> tuple[str, ...]:
    """Words to keep out of training, to measure language never trained on.

    For each meaning of each slot, every third of its one-word phrases that are
    not the dataset's own words (in the lexicon's order, from the second on):
    a rule on the lexicon alone, chosen before looking at any test sentence.
    ``lexicon.without(*held_out_words())`` is the lexicon of the training
    ``PGAE-BERT-phrasings-held-out``.
    """
    lex = lexicon or LEXICON
    dataset_words = {w for word in VOCABULARY for w in words_of(word)}
    held: dict[str, None] = {}
    for slot in SLOTS:
        for phrases in lex.phrases(slot).values():
            single = [p for p in phrases if len(words_of(p)) == 1 and p not in dataset_words]
            held.update(dict.fromkeys(single[1::3]))
    return tuple(held)


#: Which words a training's phrasings use: the whole lexicon, or less held_out_words().
PHRASING_WORDS = ("all", "held-out")


def training_lexicon(phrasing_words: str = "all") -> "PhraseLexicon":
    """The lexicon a training's phrasings use (``PhrasingsConfig.words``): all of it, or less
    :func:`held_out_words`."""
    return LEXICON.without(*held_out_words()) if phrasing_words == "held-out" else LEXICON


def _entries(value) -> list[str]:
    if isinstance(value, dict):
        return [t for v in value.values() for t in v]
    return list(value)


def words_of(text: str) -> list[str]:
    """Lower-case words of ``text``; hyphens and punctuation split words. ``text`` must be a string."""
    if not isinstance(text, str):
        raise LanguageError(f"the text must be a string, e.g. 'push the red cube'; got {type(text).__name__} "
                            f"{text!r:.80}")
    return re.findall(r"[a-z']+", text.lower())


#: The lexicon, written from general English for this purpose.
LEXICON = PhraseLexicon(
    verbs={"push": ("push", "shove", "press", "thrust", "propel", "prod"),
           "pull": ("pull", "drag", "draw", "tug", "haul"),
           "slide": ("slide", "glide", "skid", "sweep", "scoot", "slip")},
    steered={"push": ("send",), "pull": ("bring",), "slide": ()},
    neutral=("move", "shift", "nudge", "get", "take", "budge"),
    directions={
        "push": ("up", "away", "forward", "forwards", "ahead",
                 "onward", "away from you", "away from yourself", "further away",
                 "farther away", "to the far side", "toward the far edge",
                 "out in front of you", "up the table", "straight ahead"),
        "pull": ("down", "back", "backward", "backwards", "closer",
                 "nearer", "toward you", "towards you", "toward yourself",
                 "towards yourself", "to you", "in close", "closer to you",
                 "back toward you", "down the table", "your way", "to the near side"),
        "slide": ("sideways", "aside", "across", "over",
                  "to the side", "to one side", "off to the side", "sidewise",
                  "laterally", "across the table", "along the table",
                  "over to the side", "to the side a bit")},
    particles=("up", "down", "away", "forward", "back", "aside", "over", "across",
               "sideways"),
    motions={"push": ("push", "shove", "prod"), "pull": ("pull", "tug"), "slide": ()},
    colours={
        "red": _shades("red", SYNONYMS["red"], "crimson", "ruby", "cherry red",
                       "blood red", "brick red", "vermilion", "carmine", "tomato red",
                       "maroon", "reddish", "fire engine red", "strawberry red"),
        "green": _shades("green", SYNONYMS["green"], "emerald", "lime", "lime green",
                         "grass green", "leaf green", "forest green", "jade",
                         "olive green", "kelly green", "pea green", "apple green",
                         "moss green", "shamrock green", "chartreuse"),
        "blue": _shades("blue", SYNONYMS["blue"], "navy", "navy blue", "cobalt",
                        "sapphire", "royal blue", "sky blue", "ultramarine",
                        "cornflower blue", "denim blue", "midnight blue",
                        "ocean blue", "electric blue"),
        "yellow": _shades("yellow", SYNONYMS["yellow"], "blond", "golden", "gold",
                          "lemon", "lemon yellow", "canary yellow", "sunflower yellow",
                          "mustard", "banana yellow", "butter yellow", "saffron",
                          "yellowish", "amber", "sunshine yellow"),
        "cyan": _shades("cyan", _spaced("cyan"), "turquoise", "aqua", "aquamarine",
                        "teal", "blue green", "blue-green", "bluish green",
                        "aqua blue", "peacock blue", "turquoise blue", "tiffany blue",
                        "cyan blue"),
        "violet": _shades("violet", SYNONYMS["violet"], *_shades("purple")[1:],
                          "lilac", "lavender", "mauve", "plum", "amethyst", "orchid",
                          "grape", "aubergine", "eggplant", "purplish",
                          "heliotrope"),
    },
    speeds={
        "slowly": ("slowly", SYNONYMS["slowly"], "slow", "gently", "carefully",
                   "gradually", "leisurely", "steadily", "calmly", "lazily",
                   "sluggishly", "at a slow pace", "at a leisurely pace",
                   "at a gentle pace", "at an easy pace", "at low speed",
                   "at a snail's pace", "in slow motion", "little by little",
                   "bit by bit", "taking your time", "without hurrying",
                   "with no rush", "nice and slow", "at a crawl", "with care",
                   "slow and steady", "with great care", "inch by inch"),
        "fast": ("fast", SYNONYMS["fast"], "quick", "rapidly", "swiftly", "speedily",
                 "briskly", "hastily", "hurriedly", "at speed", "at high speed",
                 "at full speed", "at top speed", "at a fast pace", "at a brisk pace",
                 "as fast as you can", "as quickly as possible", "in a hurry",
                 "in a rush", "in a flash", "with haste", "in one quick motion",
                 "like lightning", "real quick", "at great speed", "in a jiffy",
                 "fast and hard", "with a burst of speed")},
    adjectives={"slowly": ("slow", "gentle", "leisurely", "unhurried", "careful",
                           "gradual", "steady", "lazy"),
                "fast": ("quick", "fast", "rapid", "swift", "brisk", "speedy", "hasty",
                         "sharp", "sudden")},
    nouns=("cube", "block", "box", "brick", "object", "thing", "item", "piece",
           "cuboid", "toy block", "square block"),
    sizes=("small", "little"),
    determiners=("the", "the", "the", "that", "this"),
    frames=("{}", "{}", "please {}", "{}, please", "{} please", "kindly {}",
            "could you {}?", "could you please {}?", "can you {}?", "would you {}?",
            "will you {}?", "would you please {}?", "I'd like you to {}",
            "I would like you to {}", "I want you to {}", "I need you to {}",
            "you should {}", "try to {}", "go ahead and {}", "be so kind as to {}",
            "let's {}", "your task is to {}", "it's time to {}", "please could you {}?",
            "do me a favour and {}", "I'd appreciate it if you would {}",
            "make sure you {}", "you can {}", "your job is to {}", "we need you to {}",
            "I'd like to see you {}"),
    gerund_frames=("would you mind {}?", "how about {}?", "try {}", "start {}"),
    carriers=("{}", "{}", "{}", "NICO, {}", "hey NICO, {}", "robot, {}",
              "hey robot, {}",
              "now {}", "now, {}", "OK, {}", "okay, {}", "alright, {}", "next, {}",
              "right, {}", "so, {}", "{}, NICO", "{} now", "{}, thanks",
              "{}, thank you",
              "okay NICO, {}", "next task: {}", "listen, {}", "NICO: {}"),
)


__all__ = ["LEXICON", "MEANINGS", "PHRASING_WORDS", "PhraseLexicon", "SLOTS", "held_out_words", "training_lexicon",
           "words_of"]
