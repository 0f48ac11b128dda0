"""The chapters' plotting and table helpers: right content, figures returned, nothing shown."""

import matplotlib

matplotlib.use("Agg")  # before pyplot is imported anywhere in this process

import numpy as np
import pytest
import torch
from matplotlib.figure import Figure

from pgae_lite.data.normaliser import Normaliser
from pgae_lite.data.toy import toy_dataset
from pgae_lite.evaluate.table1 import Predictions
from pgae_lite.model.signals import make_batch
from pgae_lite.viz import (
    plot_gates,
    plot_history,
    plot_joints,
    plot_vision,
    prediction_frame,
    signal_table,
    wrong_words,
)
from pgae_lite.world.words import SIGNALS


@pytest.fixture(scope="module")
def toy():
    data = toy_dataset(variations=1)
    train = data.split("train")
    return data, train, Normaliser.fit(train).tensors(train)


def test_signal_table_reads_the_five_signals(toy):
    _, train, tensors = toy
    fast = int(np.flatnonzero(train.lengths == 50)[0])
    batch = make_batch(tensors, torch.full((5,), fast), torch.arange(5), torch.zeros(5, dtype=torch.long))
    table = signal_table(batch)
    assert list(table.index) == list(SIGNALS)
    assert table.loc["describe", "language input"] == "[describe] <EOS>"
    assert table.loc["execute", "action input"] == "first step only"
    assert table.loc["repeat action", "action input"] == "whole sequence (50 steps)"
    assert table.loc["execute", "language target"] == "<EOS>"
    assert table.loc["describe", "action target"].startswith("final pose, held")
    assert table.loc["repeat language", "action target"].startswith("first pose, held")
    assert table.loc["repeat both", "action target"] == "recorded sequence, 50 steps"


def test_wrong_words_treats_synonyms_as_equal():
    assert wrong_words("push red slowly", "move-up scarlet unhurriedly") == ""
    assert wrong_words("push red slowly", "move-up blue slowly") == "colour"
    assert wrong_words("push red slowly", "pull red fast") == "action, speed"
    assert wrong_words("push red slowly", "") == "<EOS> only"
    assert wrong_words("", "push") == "1 word"


def test_prediction_frame(toy):
    data, _, _ = toy
    test = data.split("test")
    n = len(test)
    text = ["" for _ in range(n)]
    pred = Predictions("describe", test.ids, text, np.zeros((n, 100, 5)), np.zeros((n, 100, 5)),
                       np.zeros(n, dtype=bool), np.zeros((n, 50)))
    frame = prediction_frame(pred, test)
    assert len(frame) == n and set(frame.action) == {"push", "pull", "slide"}
    assert set(frame.side) == {"left cube", "right cube"} and (frame.wrong == "<EOS> only").all()
    eos = prediction_frame(Predictions("execute", test.ids, text, pred.joints, pred.target,
                                       np.ones(n, dtype=bool), pred.gate), test)
    assert (eos.expected == "").all() and (eos.wrong == "").all()


def test_plots_return_figures():
    history = [{"epoch": e, "loss": 1.0 / e, "language_loss": 0.9 / e, "action_loss": 0.1 / e,
                "gate": {s: 0.5 for s in SIGNALS}} for e in (1, 2, 3)]
    joints = np.random.default_rng(0).random((100, 5))
    figures = [plot_gates({s: np.full((4, 50), 0.3) for s in SIGNALS}), plot_history(history),
               plot_joints(joints, joints, 50, "t"), plot_vision(np.zeros((100, 30)), 50)]
    assert all(isinstance(f, Figure) for f in figures)


# --------------------------------------------------------------------------- the world: frames, animations, patterns
def test_plot_frames_draws_count_frames_per_row():
    from pgae_lite.viz import plot_frames

    frames = np.zeros((10, 12, 16, 3), dtype=np.uint8)
    fig = plot_frames({"a": frames, "b": frames[:5]}, count=4)
    assert isinstance(fig, Figure) and len(fig.axes) == 8
    assert [ax.get_title() for ax in fig.axes[:4]] == ["t = 0", "t = 3", "t = 6", "t = 9"]
    assert fig.axes[4 + 3].get_title() == "t = 4"                 # each row spans its own sequence
    with pytest.raises(ValueError, match="empty"):
        plot_frames({})


def test_animate_frames_plays_every_nth_step_and_embeds_offline():
    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation

    from pgae_lite.viz import animate_frames

    frames = np.random.default_rng(0).integers(0, 255, (8, 12, 16, 3), dtype=np.uint8)
    anim = animate_frames({"a": frames, "b": frames[:3]}, joints=np.zeros((8, 5)), every=3, dpi=20, size=1)
    assert isinstance(anim, FuncAnimation)
    assert not plt.fignum_exists(anim._fig.number)                # closed: no second, still copy
    html = anim.to_jshtml()
    assert html.count("data:image/png;base64") == 4                # steps 0, 3, 6 and the last one, 7
    with pytest.raises(ValueError, match="empty"):
        animate_frames({})


def test_plot_patterns_labels_all_144_and_outlines_test_patterns():
    from pgae_lite.viz import plot_patterns
    from pgae_lite.world.patterns import TEST_PATTERNS

    fig = plot_patterns(marked=(0, 1, 2))
    labels = {t.get_text() for t in fig.axes[0].texts}
    assert {str(n) for n in range(144)} <= labels
    fig = plot_patterns({n: n / 143 for n in range(144)}, label="accuracy")
    assert len(fig.axes[0].patches) == len(TEST_PATTERNS)         # one outline per test pattern
    assert len(fig.axes) == 2                                      # the plot and its colour bar


def test_plot_joints_by_action_puts_each_code_in_its_panel():
    from pgae_lite.viz import plot_joints_by_action

    joints = [np.zeros((100, 5)), np.ones((50, 5)), np.ones((50, 5))]
    fig = plot_joints_by_action(joints, ["PUSH-L-SLOW", "SLIDE-R-FAST", "SLIDE-R-FAST"])
    axes = fig.axes
    assert len(axes) == 12
    assert len(axes[0].lines) == 5 + 5                             # 5 joints + 5 legend handles
    assert axes[0].get_title() == "push left, slow" and axes[11].get_title() == "slide right, fast"
    assert len(axes[11].lines) == 10 and len(axes[6].lines) == 0


# --------------------------------------------------------------------------- seeing: the CAE chapter's helpers
def test_plot_channels_shows_the_frame_and_its_three_channels():
    from pgae_lite.viz import plot_channels

    frame = np.zeros((12, 16, 3), np.uint8)
    frame[..., 1] = 200
    fig = plot_channels(frame, "title")
    assert len(fig.axes) == 4
    green = fig.axes[2].images[0].get_array()
    assert green.shape == (12, 16) and green.max() == 200 and fig.axes[1].images[0].get_array().max() == 0


def test_plot_reconstructions_one_row_per_entry_with_errors_per_channel():
    from pgae_lite.viz import plot_reconstructions

    original = np.full((12, 16, 3), 100, np.uint8)
    rebuilt = original.copy()
    rebuilt[..., 2] = 110                                          # the blue channel is 10 grey levels off
    fig = plot_reconstructions({"a": (original, rebuilt), "b": (original, original)})
    axes = np.array(fig.axes).reshape(2, 5)
    assert "error 0.0" in axes[0, 1].get_title() and "error 10.0" in axes[0, 3].get_title()
    assert axes[1, 3].get_title() == "error 0.0"
    assert axes[0, 0].get_ylabel() == "a"
    with pytest.raises(ValueError, match="empty"):
        plot_reconstructions({})


def test_plot_cae_history_panels_per_channel_and_floor_on_log_scale():
    from pgae_lite.viz import plot_cae_history

    history = [{"iteration": i + 1, "loss": 0.6, "red": 0.6 + 0.1 / (i + 1), "green": 0.6, "blue": 0.7}
               for i in range(40)]
    fig = plot_cae_history(history, smooth=4)
    assert [ax.get_title() for ax in fig.axes] == ["red channel", "green channel", "blue channel"]
    assert fig.axes[0].get_yscale() == "linear"
    smoothed = fig.axes[0].lines[1].get_ydata()
    assert np.isclose(smoothed[-1], np.mean([r["red"] for r in history[-4:]]))   # trailing mean of 4
    fig = plot_cae_history(history, floor=[0.5, 0.5, 0.5], levels={"mean image": [0.65, 0.65, 0.65]})
    assert fig.axes[0].get_yscale() == "log"
    assert np.isclose(fig.axes[2].lines[1].get_ydata()[-1], 0.2)   # BCE above the floor
    assert np.isclose(fig.axes[2].lines[2].get_ydata()[0], 0.15)   # the level, above the floor too
    with pytest.raises(ValueError, match="empty"):
        plot_cae_history([])


def test_feature_plots_draw_every_step_and_row():
    from pgae_lite.viz import plot_feature_rows, plot_features_over_time

    frames = np.zeros((20, 12, 16, 3), np.uint8)
    features = np.linspace(-1, 1, 20 * 30).reshape(20, 30)
    fig = plot_features_over_time(frames, features, joints=np.zeros((20, 5)), count=4, joint_names="abcde")
    heat = [ax for ax in fig.axes if ax.images and ax.images[0].get_array().shape == (30, 20)]
    assert len(heat) == 1                                          # features (T, F) drawn as (F, T)
    legends = [ax.get_legend() for ax in fig.axes if ax.get_legend()]
    assert [t.get_text() for t in legends[0].get_texts()] == list("abcde")
    assert sum(1 for ax in fig.axes if ax.get_title().startswith("t = ")) == 4
    fig = plot_feature_rows({"a": frames[0], "b": frames[1]}, features[:2])
    assert sum(1 for ax in fig.axes if ax.images and ax.images[0].get_array().shape == (1, 30)) == 2
    with pytest.raises(ValueError, match="2 frames but 3"):
        plot_feature_rows({"a": frames[0], "b": frames[1]}, features[:3])
