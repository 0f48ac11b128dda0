"""Hostile input, round two: writes never go through a link, the word lookup reads words, options
are range-checked, and a checkpoint with broken weights is refused (each a reproduction of a report)."""
from __future__ import annotations

import math
import os
from dataclasses import replace

import pytest
import torch
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from pgae_lite.model.config import ModelConfig
from pgae_lite.train.config import TrainConfig
from pgae_lite.util.storage import OutputError, atomic_write_text


# --------------------------------------------------------------------------- writes
def test_a_write_never_goes_through_a_symbolic_link(tmp_path):
    victim = tmp_path / "victim"
    victim.write_text("precious")
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "README.md").symlink_to(victim)
    with pytest.raises(OutputError, match=r"refusing to write .*README.md: it is a symbolic link"):
        atomic_write_text(tmp_path / "out" / "README.md", "overwritten")
    assert victim.read_text() == "precious"


def test_reproduce_refuses_a_planted_link_and_a_file_for_its_folder(tmp_path, original_data):
    from pgae_lite.runs.reproduce import reproduce

    victim, out = tmp_path / "victim", tmp_path / "o"
    victim.write_text("precious")
    out.mkdir()
    (out / "predictions.npz").symlink_to(victim)
    with pytest.raises(OutputError, match="predictions.npz: it is a symbolic link"):
        reproduce(original_data, profile="smoke", out_dir=out, progress=False, device="cpu")
    assert victim.read_text() == "precious"
    (tmp_path / "afile").write_text("")
    with pytest.raises(OutputError, match="cannot use .*afile as an output folder: a file of that name"):
        reproduce(original_data, profile="smoke", out_dir=tmp_path / "afile", progress=False, device="cpu")


# --------------------------------------------------------------------------- the word lookup
@pytest.fixture(scope="module")
def lookup():
    pytest.importorskip("wn")
    from pgae_lite.freeform.phrase_lexicon import training_lexicon
    from pgae_lite.freeform.word_lookup import WordLookup

    return WordLookup(training_lexicon("held-out"))


def test_careless_spelling_is_not_read_as_colours(lookup):
    text = "slide the blue cube s l o w l y, fåst, o.k.?"
    assert lookup.rewrite(text) == text
    assert lookup.rewrite("could you draw the amethyst block closer?") == "could you pull the purple block closer?"


KNOWN = ["push", "pull", "slide", "red", "blue", "slowly", "fast", "the", "cube", "please", "quickly"]


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.lists(st.one_of(st.sampled_from(KNOWN), st.text(min_size=1, max_size=6)), min_size=1, max_size=8))
def test_the_lookup_never_changes_a_known_word_nor_a_fragment(lookup, parts):
    text = " ".join(parts)
    for word, replacement in lookup.replacements(text).items():
        assert word.isascii() and word.isalpha() and len(word) >= 3, (text, word)   # a word, not a fragment
        assert not lookup.is_known(word.lower()), (text, word)
        assert replacement
    for word in KNOWN:                     # a word the model knows stays as it is, wherever it stands
        assert word not in lookup.replacements(f"{text} {word}")


# --------------------------------------------------------------------------- options
@pytest.mark.parametrize("option, value, message", [
    ("warmup", 5, "warmup must be a number >= 0 and <= 0.99"),
    ("schedule", "linear", "unknown schedule 'linear'; the options are: cosine, constant"),
    ("language_weight", -1, "language_weight must be a number >= 0"),
    ("opposite_prob", 5, "opposite_prob must be a number >= 0 and <= 1"),
    ("clip", -1, "clip must be a number > 0 or None"),
    ("lr", math.nan, "lr must be a number > 0"),
    ("teacher_language", "yes", "teacher_language must be True or False"),
])
def test_training_options_are_range_and_choice_checked(option, value, message):
    with pytest.raises(ValueError, match=message):
        TrainConfig(**{option: value})


@pytest.mark.parametrize("option, value, message", [
    ("units", 0, "units must be a whole number >= 1"), ("hidden", 2.5, "hidden must be a whole number"),
    ("cell", "gru", "unknown cell 'gru'"), ("joint_feedback", "own", "unknown joint_feedback 'own'"),
])
def test_model_options_are_checked(option, value, message):
    with pytest.raises(ValueError, match=message):
        ModelConfig(**{option: value})


def test_the_built_in_profiles_pass_their_own_checks():
    from pgae_lite.config import PROFILES

    for profile in PROFILES.values():
        replace(profile.train)            # runs __post_init__ again
        replace(profile.model)


# --------------------------------------------------------------------------- checkpoints
def test_a_checkpoint_with_non_finite_weights_is_refused(tmp_path, toy_short):
    from pgae_lite.config import get_profile
    from pgae_lite.runs.pipeline import load_model
    from pgae_lite.train.checkpoint import CHECKPOINT
    from pgae_lite.train.loop import train
    from pgae_lite.util.storage import CorruptCheckpointError

    profile = get_profile("smoke")
    profile.train = replace(profile.train, epochs=1)
    train(toy_short, profile, out_dir=tmp_path, progress=False, device="cpu")
    ckpt = torch.load(tmp_path / CHECKPOINT, weights_only=True)
    name = next(k for k, v in ckpt["model"].items() if v.is_floating_point())
    ckpt["model"][name][...] = math.nan
    torch.save(ckpt, tmp_path / CHECKPOINT)
    with pytest.raises(CorruptCheckpointError, match="holds non-finite weights .* train it again"):
        load_model(tmp_path / CHECKPOINT, device="cpu")
    assert os.path.exists(tmp_path / CHECKPOINT)          # refused, not deleted


# --------------------------------------------------------------------------- more inputs of the report
def test_a_pattern_outside_the_world_is_refused():
    from pgae_lite.world.colours import DEFAULT_WORLD

    with pytest.raises(ValueError, match="arrangement must be a whole number from 0 to 11 in this world; got 99"):
        DEFAULT_WORLD.pattern_number(0, 99, 0)
    assert DEFAULT_WORLD.pattern_number(1, 11, 5) == 143


def test_readbacks_and_instructions_must_pair_up():
    from pgae_lite.robot.instructions import acted_on

    with pytest.raises(ValueError, match="one readback per instruction; got 1 readbacks for 2 instructions"):
        acted_on(["push red fast"], ["shove the red cube", "pull it"])


def test_is_correct_wants_a_text():
    from pgae_lite.world.words import LanguageError, is_correct

    with pytest.raises(LanguageError, match="compares a generated text"):
        is_correct(None, [("push", "red", "fast")])


def test_the_cache_variable_naming_a_file_or_empty_is_one_sentence(tmp_path, monkeypatch):
    from pgae_lite.util.storage import CACHE_ENV, cache_dir

    (tmp_path / "afile").write_text("")
    monkeypatch.setenv(CACHE_ENV, str(tmp_path / "afile"))
    with pytest.raises(OutputError, match="is a file; name a folder"):
        cache_dir()
    monkeypatch.setenv(CACHE_ENV, "")
    with pytest.raises(OutputError, match="is set but empty"):
        cache_dir()
