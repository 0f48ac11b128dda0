"""Hostile and careless input to the command line and the public API (issue 21).

Each bad input gets one clear sentence that names the argument and what is
allowed: the command line prints ``error: ...`` and exits with status 2, no
traceback (run as ``python -m pgae_lite``, with arguments refused before any
data is read); the functions raise the package's errors. Hypothesis checks the
description parser and ``encode``/``decode`` on valid and on arbitrary input.
"""
from __future__ import annotations

import functools
import importlib
import inspect
import json
import pkgutil

import numpy as np
import pytest
import torch
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_cli import run as run_cli

import pgae_lite
from pgae_lite.bert.pretrained import PretrainedLanguageEncoder, load_transformer
from pgae_lite.config import PROFILE_ENV, ModelConfig, get_profile, profile_name
from pgae_lite.data.normaliser import Normaliser
from pgae_lite.evaluate.table1 import Predictions, evaluate, format_table, nrmse, predict
from pgae_lite.model.pgae import PGAE
from pgae_lite.robot.instructions import instruction_features
from pgae_lite.robot.playground import (
    Playground,
    PlayResult,
    action_label,
    arrangement_label,
    find_episode,
    play,
    scene_pattern,
    simulator_config,
)
from pgae_lite.robot.playground_checks import LAST_PATTERN
from pgae_lite.runs.data import simulated_dataset
from pgae_lite.runs.reproduce import reproduce, write_results
from pgae_lite.util.errors import ArgumentError, ArgumentTypeError, PGAELiteError
from pgae_lite.world.patterns import ARRANGEMENTS
from pgae_lite.world.words import (
    BOS_EOS,
    SLOTS,
    SYNONYMS,
    VOCABULARY,
    LanguageError,
    decode,
    encode,
    one_hot,
    parse_description,
)

WORDS = [w for w in VOCABULARY if w != BOS_EOS]
ARRANGEMENT, ACTION = 7, 8          # cyan left, yellow right; slide the left cube fast
LAST_WORD, LAST_ARRANGEMENT = len(VOCABULARY) - 1, len(ARRANGEMENTS) - 1     # 22, 11


def refused(r, *needles):
    """A command line run refused with status 2, one clear message and no traceback."""
    assert r.returncode == 2, (r.returncode, r.stderr)
    assert "Traceback" not in r.stderr and r.stdout == ""
    for needle in needles:
        assert needle in r.stderr, (needle, r.stderr)
    return r.stderr


@pytest.fixture(scope="module")
def tiny(toy):
    torch.manual_seed(0)
    model = PGAE(ModelConfig(units=16, hidden=8, joint_feedback="predicted")).eval()
    return model, Normaliser.fit(toy.split("train"))


# ------------------------------------------------------------------- command line
@pytest.mark.parametrize("args, message", [
    (["--epochs", "0"], "--epochs must be a whole number >= 1; got 0"),  # was: 1,200
    (["--epochs", "-5"], "--epochs must be a whole number >= 1; got -5"),
    (["--original-data", ""], "--original-data is empty"),       # was: simulated data
    (["--out", ""], "--out is empty"),
    (["--pretrained-model", "my/model"], "--pretrained-model 'my/model' is the pretrained language model of PGAE-BERT"),
    (["--device", "garbage"], "--device 'garbage' is not a torch device; use cpu"),
    (["--seeds", "1000000000000"], "--seeds must be a whole number from 1 to 100"),
    (["--seed", str(2 ** 32)], "--seed must be a whole number from 0 to 4294967295"),
    (["--seed", str(2 ** 32 - 1), "--seeds", "2"], "reaches seed 4294967296"),
], ids=["epochs-0", "epochs-negative", "empty-data", "empty-out",
        "pretrained-without-bert", "device-garbage", "too-many-seeds", "seed-too-large",
        "seeds-past-the-limit"])
def test_a_bad_reproduce_argument_is_refused_before_any_data(args, message):
    refused(run_cli("reproduce", *args, "--no-progress"), message)


@pytest.mark.skipif(torch.cuda.is_available(), reason="this machine has CUDA")
def test_cuda_without_cuda_is_refused():
    refused(run_cli("reproduce", "--device", "cuda"),
            "--device 'cuda' is not available")


def test_an_empty_data_variable_is_refused():
    refused(run_cli("reproduce", env={"PGAE_ORIGINAL_DATA": ""}),
            "PGAE_ORIGINAL_DATA is set but empty; unset it to use our simulated data")


def test_simulate_refuses_zero_workers():
    refused(run_cli("simulate", "--workers", "0"),
            "--workers must be a whole number >= 1")


def test_a_package_error_is_one_line_without_a_traceback(tmp_path):
    """A missing PGAE-BERT model (PretrainedModelError), refused before any data."""
    missing = tmp_path / "no-model"
    err = refused(run_cli("reproduce", "--rows", "PGAE-BERT",
                          "--pretrained-model", missing))
    assert err.splitlines() == [f"error: no model folder at '{missing}' (it should "
                                "hold config.json, the weights and the tokenizer "
                                "files)"]


def test_every_error_of_the_package_is_a_pgae_lite_error():
    """The command line catches PGAELiteError: every error class of ours is one."""
    found = []
    for info in pkgutil.walk_packages(pgae_lite.__path__, "pgae_lite."):
        module = importlib.import_module(info.name)
        for cls in vars(module).values():
            ours = inspect.isclass(cls) and cls.__module__ == info.name
            if ours and issubclass(cls, BaseException):
                found.append(cls)
                assert issubclass(cls, PGAELiteError), cls
    names = {c.__name__ for c in found}
    assert {"LanguageError", "DataFormatError", "DataMismatchError", "ArgumentError",
            "CheckpointMismatchError", "PretrainedModelError",
            "CorruptEpisodeError"} <= names
    assert issubclass(LanguageError, ValueError)
    assert issubclass(ArgumentTypeError, TypeError)


def test_an_unknown_profile_is_clear_from_every_entry_point(monkeypatch):
    listed = "the profiles are: smoke, book, paper"
    monkeypatch.delenv(PROFILE_ENV, raising=False)
    for call in (lambda: get_profile("garbage"), lambda: profile_name(5)):
        with pytest.raises(ArgumentError, match=listed):
            call()
    with pytest.raises(ArgumentTypeError, match="profile must be a Profile, resolved once where the run starts: "
                                                "pgae_lite.config.get_profile\\(name\\); got str 'garbage'"):
        simulated_dataset("garbage")                      # below the entry points a profile is a value
    monkeypatch.setenv(PROFILE_ENV, "garbage")
    with pytest.raises(ArgumentError, match=f"variable {PROFILE_ENV}.*{listed}"):
        get_profile()
    refused(run_cli("simulate", "--profile", "garbage"), "invalid choice: 'garbage'")


def test_results_json_is_strict_json(tmp_path):
    report = {"rows": {"PGAE": {"mean": {"describe": {"accuracy": float("nan"),
                                                      "nrmse": float("inf"), "n": 0}}}},
              "seeds": [0], "wall_seconds": 1.5}
    path = tmp_path / "results.json"
    assert write_results(path, report) == 2

    def no_constants(name):
        raise AssertionError(f"results.json holds {name}")

    loaded = json.loads(path.read_text(), parse_constant=no_constants)
    cell = loaded["rows"]["PGAE"]["mean"]["describe"]
    assert cell == {"accuracy": None, "nrmse": None, "n": 0}
    assert loaded["seeds"] == [0] and loaded["wall_seconds"] == 1.5


@pytest.mark.parametrize("kwargs, error, message", [
    (dict(epochs=0), ArgumentError, "epochs must be a whole number >= 1; got 0"),
    (dict(seed=-1), ArgumentError, "seed must be a whole number from 0"),
    (dict(seeds=2.5), ArgumentTypeError, "seeds must be a whole number"),
    (dict(rows=[]), ArgumentError, "rows is empty"),
    (dict(original_data=" "), ArgumentError, "original_data is empty"),
    (dict(pretrained_model="my/model"), ArgumentError, "pretrained_model 'my/model'"),
    (dict(device="garbage"), ArgumentError, "device 'garbage' is not a torch device"),
])
def test_reproduce_checks_its_arguments_before_reading_data(kwargs, error, message):
    """No such data folder: an argument checked later would raise DataFormatError."""
    with pytest.raises(error, match=message):
        reproduce(**{"original_data": "/no/such/folder", **kwargs})


# ------------------------------------------------------------------- language
def test_encode_names_the_bad_word():
    with pytest.raises(LanguageError, match="encode got 'pink' at position 1, not a "
                                            "word of the vocabulary: azure"):
        encode(["push", "pink"])
    with pytest.raises(LanguageError, match="a list of vocabulary words.*got str"):
        encode("push red slowly")


@pytest.mark.parametrize("indices, message", [
    ([3, -1], "got -1 at position 1"),       # was: 'blue yellow' (-1 wraps around)
    ([14, 30], "got 30 at position 1"),
    ([14, 1.5], "got 1.5 at position 1"),
    ([True, 3], "True or False"),
    ([[1, 2], [3]], r"got \[\[1, 2\], \[3\]\]"),
    ([[1, 2]], r"2-D torch.int64 of shape \(1, 2\)"),
    ("push", "got the text 'push'"),
    ([None], r"got \[None\]"),
    (7, "0-D"),
])
def test_decode_refuses_malformed_input(indices, message):
    wanted = rf"decode takes word indices \(whole numbers 0-{LAST_WORD}\).*"
    with pytest.raises(LanguageError, match=wanted + message):
        decode(indices)


def test_parse_description_wants_text():
    with pytest.raises(LanguageError, match="must be a string.*got list"):
        parse_description(["push", "red", "slowly"])


def test_encode_texts_refuses_a_string():
    encoder = PretrainedLanguageEncoder()
    with pytest.raises(LanguageError, match="a list of texts, one per sentence, e.g. "
                                            r"\['push red slowly'\]; got the string"):
        encoder.encode_texts("push red slowly")          # was: one text per character
    with pytest.raises(LanguageError, match="got 5 at position 1"):
        encoder.encode_texts(["push red slowly", 5])
    assert encoder.encode_texts(("push red slowly",)).shape == (1, encoder.output_dim)


def test_the_texts_and_the_model_name_are_checked(tiny):
    with pytest.raises(LanguageError, match="instruction_features takes a list"):
        instruction_features(tiny[0], "push red slowly")
    with pytest.raises(ArgumentError, match="name is empty"):
        load_transformer("")
    with pytest.raises(ArgumentTypeError, match="a Hugging Face name or a folder"):
        PretrainedLanguageEncoder(5)


slot_word = [st.sampled_from([w for c in slot for w in (c, SYNONYMS[c])])
             for slot in SLOTS]
CANONICAL = {**{w: w for w in SYNONYMS}, **{s: w for w, s in SYNONYMS.items()}}


@given(st.tuples(*slot_word), st.sampled_from([" ", "  ", ", ", " ; "]), st.booleans())
def test_parse_description_round_trip(words, separator, upper):
    text = separator.join(w.replace("-", " ") for w in words)
    canonical = tuple(CANONICAL[w] for w in words)
    assert parse_description(text.upper() if upper else text) == canonical


@given(st.one_of(st.text(),
                 st.lists(st.sampled_from(WORDS + ["the", "cube", "."])).map(" ".join),
                 st.none(), st.integers(), st.lists(st.text())))
def test_parse_description_accepts_or_says_why(text):
    try:
        words = parse_description(text)
    except LanguageError as e:
        assert str(e)
    else:
        assert all(w in slot for w, slot in zip(words, SLOTS)) and len(words) == 3


@given(st.lists(st.sampled_from(WORDS), max_size=8))
def test_encode_decode_round_trip(words):
    indices = encode(words)
    assert decode(indices[1:]) == " ".join(words)
    assert decode(one_hot(indices[1:])) == " ".join(words)
    assert decode(indices[1:].tolist()) == " ".join(words)


@given(st.lists(st.one_of(st.sampled_from(WORDS), st.text(max_size=12), st.integers())))
def test_encode_accepts_or_says_why(words):
    try:
        indices = encode(words)
    except LanguageError as e:
        assert "not a word of the vocabulary" in str(e)
        assert not all(isinstance(w, str) and w in WORDS for w in words)
    else:
        assert len(indices) == len(words) + 2


anything = st.recursive(st.one_of(st.integers(), st.floats(), st.booleans(), st.none(),
                                  st.text(max_size=5)),
                        functools.partial(st.lists, max_size=5), max_leaves=12)


@given(anything)
def test_decode_accepts_or_says_why(indices):
    try:
        text = decode(indices)
    except LanguageError as e:
        assert str(e).startswith("decode takes word indices")
    else:
        assert set(text.split()) <= set(WORDS)


@given(st.lists(st.integers(-2 ** 70, 2 ** 70), max_size=6))
def test_decode_reads_exactly_the_indices_0_to_22(indices):
    if all(0 <= i < len(VOCABULARY) for i in indices):
        words = indices[:(indices + [0]).index(0)]             # up to the first <EOS>
        assert decode(indices) == " ".join(VOCABULARY[i] for i in words)
    else:
        with pytest.raises(LanguageError, match=f"whole numbers 0-{LAST_WORD}"):
            decode(indices)


# ------------------------------------------------------------------- evaluation
def test_evaluation_checks_its_arguments(tiny, toy):
    model, normaliser = tiny
    few = toy.subset(np.arange(3))
    positive = "joint_range must be a finite number > 0; got"
    with pytest.raises(ArgumentError, match=f"{positive} 0"):
        evaluate(model, toy, normaliser, joint_range=0)          # was: the data's range
    with pytest.raises(ArgumentError, match="batch_size must be a whole number >= 1"):
        predict(model, few, normaliser, "describe", batch_size=0)
    with pytest.raises(ArgumentError, match=r"language must be .* shape \(3, D\)"):
        predict(model, few, normaliser, "execute", language=torch.zeros(2, 8))
    with pytest.raises(ArgumentTypeError, match="normaliser must be a Normaliser"):
        predict(model, few, "normaliser", "describe")
    joints = np.zeros((1, 3, 5))
    pred = Predictions("describe", np.array(["a"]), [""], joints, joints,
                       np.array([True]), np.zeros((1, 8)))
    with pytest.raises(ArgumentError, match=f"{positive} nan"):
        nrmse(pred, float("nan"))
    cells = {s: {"accuracy": 1.0, "nrmse": 0.1, "nrmse_padded": 0.1}
             for s in ("describe", "repeat language", "execute", "repeat action")}
    with pytest.raises(ArgumentError, match="'GPT', not a row of the paper's Table 1"):
        format_table({"ours": cells}, {"ours": "GPT"})
    with pytest.raises(ArgumentError, match="lack the signal\\(s\\) execute"):
        format_table({"ours": {s: c for s, c in cells.items() if s != "execute"}})


# ------------------------------------------------------------------- playground
def test_play_refuses_choices_out_of_range(tiny, toy):
    model, normaliser = tiny
    beyond = LAST_ARRANGEMENT + 1
    with pytest.raises(ArgumentError, match=f"arrangement must be a whole number from "
                                            f"0 to {LAST_ARRANGEMENT}; got {beyond}"):
        play(model, None, normaliser, toy, "execute", beyond, 0, loop=None)  # was: 72
    with pytest.raises(ArgumentError, match="action must be a whole number from 0 to "
                                            "11; got -1"):
        play(model, None, normaliser, toy, "execute", 0, -1, loop=None)
    with pytest.raises(ArgumentError, match="variation must be .* >= 0; got -1"):
        play(model, None, normaliser, toy, "execute", 0, 0, variation=-1,
             loop=None)                                         # was: the last one
    with pytest.raises(ValueError, match="1 recording.*no variation 1"):
        play(model, None, normaliser, toy, "execute", 0, 0, variation=1, loop=None)


@pytest.mark.parametrize("value", [1.5, "3", True, None])
@pytest.mark.parametrize("argument", ["arrangement", "action", "variation"])
def test_play_refuses_choices_that_are_not_whole_numbers(tiny, toy, argument, value):
    model, normaliser = tiny
    choice = {"arrangement": ARRANGEMENT, "action": ACTION, "variation": 0,
              argument: value}
    with pytest.raises(ArgumentTypeError, match=f"{argument} must be a whole number"):
        play(model, None, normaliser, toy, "execute", choice["arrangement"],
             choice["action"], variation=choice["variation"], loop=None)


def test_every_public_playground_function_checks_its_arguments(tiny, toy):
    model, normaliser = tiny
    beyond = LAST_ARRANGEMENT + 1
    checks = [
        (lambda: arrangement_label(-1), ArgumentError, "arrangement .* got -1"),
        (lambda: action_label(12), ArgumentError, "action .* 0 to 11; got 12"),
        (lambda: scene_pattern(0, 2.0), ArgumentTypeError, "action must be a whole"),
        (lambda: find_episode(toy, LAST_PATTERN + 1), ArgumentError,
         f"pattern .* 0 to {LAST_PATTERN}; got {LAST_PATTERN + 1}"),
        (lambda: simulator_config("data"), ArgumentTypeError, "data must be a PGAE"),
        (lambda: play("model", None, normaliser, toy), ArgumentTypeError,
         "model must be a model"),
        (lambda: play(model, "cae", normaliser, toy), ArgumentTypeError,
         "cae must be a Channel"),
        (lambda: play(model, None, normaliser, toy, text=["push"]), ArgumentTypeError,
         "text must be a description"),
        (lambda: Playground({}, None, toy), ArgumentError, "models is empty"),
        (lambda: Playground({"PGAE": model}, None, toy), ArgumentTypeError,
         r"models\['PGAE'\] must be a \(model, normaliser\) pair; got a PGAE"),
        (lambda: Playground({"PGAE": tiny}, None, toy, arrangement=beyond),
         ArgumentError, f"arrangement must be .* got {beyond}"),
        (lambda: Playground({"PGAE": tiny}, None, toy.subset(np.arange(6)),
                            arrangement=7),
         ArgumentError, "arrangement 7 is not in this dataset; its arrangements are"),
        (lambda: Playground({"PGAE": tiny}, None, toy, signal="repeat both"),
         ArgumentError, "signal 'repeat both' is not offered here"),
        (lambda: Playground({"PGAE": tiny}, None, toy, every=0), ArgumentError,
         "every must be"),
    ]
    for call, error, message in checks:
        with pytest.raises(error, match=message):
            call()
    result = play(model, None, normaliser, toy, "describe", ARRANGEMENT, ACTION,
                  loop=None)
    assert isinstance(result, PlayResult)
    with pytest.raises(ArgumentError, match="every must be a whole number >= 1; got 0"):
        result.animation(every=0)
    with pytest.raises(ArgumentError, match="size must be a finite number > 0"):
        result.animation(size=-1.0)


sentences = st.one_of(st.text(max_size=40),
                      st.lists(st.sampled_from(WORDS + ["the", "cube", "please", "!"]),
                               max_size=5).map(" ".join))


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(text=sentences)
def test_the_free_text_box_never_shows_a_traceback(tiny, toy, text):
    ui = Playground({"PGAE": tiny}, None, toy, arrangement=ARRANGEMENT, action=ACTION)
    ui.loop.value, ui.text.value = None, text
    ui.button.click()                                   # no exception escapes the click
    assert (ui.result is None) != (ui.message == "")
    shown = "".join(str(o["data"].get("text/html", "")) for o in ui.output.outputs)
    assert "Traceback" not in shown
