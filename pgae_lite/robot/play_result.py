"""What one call of the playground's ``play`` produced, and how it is shown.

Paper, Sec. 3 ("Signals") and Sec. 4 (Table 1's tasks): the words a signal asks for (a
description, or ``<EOS>`` alone), the joints it asks for (:data:`TARGETS`), the GMU gate, and
the simulator's execution of the joints (:mod:`pgae_lite.robot.closedloop`).
"""
from __future__ import annotations

import html
import io
import textwrap
from dataclasses import dataclass

import matplotlib.pyplot as plt
import numpy as np
import torch
from matplotlib.figure import Figure

from pgae_lite.model.signals import LANG_OUT
from pgae_lite.sim.record import Execution
from pgae_lite.util.checks import positive_number, whole_number
from pgae_lite.viz import animate_frames, plot_joints
from pgae_lite.world.patterns import Pattern
from pgae_lite.world.words import SIGNALS, VOCABULARY

#: What the joints of each signal should be (the action decoder's target, from the recorded episode).
TARGETS: dict[str, str] = {"describe": "the final recorded pose, held", "execute": "the recorded joints",
                           "repeat action": "the recorded joints", "repeat both": "the recorded joints",
                           "repeat language": "the first recorded pose, held"}

#: What each signal asks the words to be (the paper's criterion, :func:`~pgae_lite.world.words.is_correct`).
EXPECTED: dict[str, str] = {s: "a description of the action" if LANG_OUT[k] else "<EOS> alone"
                            for k, s in enumerate(SIGNALS)}


def word_choices(logits: torch.Tensor) -> list[dict]:
    """How sure the language decoder was of each word it wrote, from its scores ``logits`` (steps, V).

    Per position, up to and including the first ``<BOS/EOS>`` it chose: the word (the highest
    probability, as greedy decoding picks it), its probability p = softmax(logits)[word], and the
    runner-up word and its probability. The decoder can only answer in the dataset's words: its last
    layer scores those 23 and nothing else, so even nonsense gets an answer; a low p says it was a guess.
    """
    p = torch.softmax(logits.detach().double().cpu(), -1)             # (steps, V), each row sums to 1
    best = p.topk(2, -1)                                                # (steps, 2): values and indices
    out = []
    for k in range(p.shape[0]):
        (first, second), (word, runner_up) = best.values[k].tolist(), best.indices[k].tolist()
        out.append({"word": VOCABULARY[word], "p": first, "runner_up": VOCABULARY[runner_up], "runner_up_p": second})
        if word == 0:                                                   # <BOS/EOS>: the words end here
            break
    return out


def choices_text(choices: list[dict]) -> str:
    """E.g. ``push 0.98 (pull 0.01), red 0.99 (...), ...``: each word, how sure, and its runner-up."""
    return ", ".join(f"{c['word']} {c['p']:.2f} ({c['runner_up']} {c['runner_up_p']:.2f})" for c in choices)


@dataclass
class PlayResult:
    """What one call of :func:`~pgae_lite.robot.playground.play` produced (joints in data units, steps 0..length-1)."""

    signal: str
    pattern: int
    variation: int            # the simulator's variation of the episode
    episode: str              # the episode's id in the dataset
    told: str                 # the model's language input as text, e.g. "execute push red slowly"
    words: str                # generated description, "" for <EOS> alone
    correct: bool             # the paper's criterion for this signal
    joints: np.ndarray        # (length, 5) predicted (closed loop: what the loop asked for)
    target: np.ndarray        # (length, 5) what the signal asks for (see TARGETS)
    nrmse: float              # % of the dataset's joint range, over steps 1..length-1
    gate: np.ndarray          # (hidden,) GMU gate z: 1 lets the action through, 0 the language
    rollout: Execution | None  # the simulator's execution of ``joints`` (None: not simulated)
    loop: str | None = None   # "open", "closed" or None: how the simulator ran the joints
    understood: str | None = None  # typed text said back (``repeat language``): what the model took it to mean
    note: str | None = None   # where the typed text and the chosen episode disagree, that they do
    choices: list[dict] | None = None   # how sure of each word written (word_choices)
    understood_choices: list[dict] | None = None   # the same for the readback
    route: str | None = None  # free text under execute: "direct" or "said back" (else None)
    acted_on: str | None = None  # what route "said back" executed: the readback's words (or the text itself)

    def summary(self) -> str:
        """A few lines of plain text: task, episode, words, joint error, the simulator's verdict."""
        p = Pattern.from_number(self.pattern)
        lines = [f"signal: {self.signal}   model reads: {self.told!r}",
                 f"episode {self.episode}: {p.action} the {p.colour} cube {p.speed} ({p.left} left, {p.right} right)",
                 f"words: {self.words or '<EOS>'!r} ({'right' if self.correct else 'wrong'}: expected "
                 f"{EXPECTED[self.signal]})",
                 f"joints: nRMSE {self.nrmse:.2f}% against {TARGETS[self.signal]}; "
                 f"mean gate z {self.gate.mean():.2f} (0 = language, 1 = action)"]
        if self.choices:
            lines.insert(3, f"how sure of each word: {choices_text(self.choices)}")
        if self.understood is not None:
            said = self.understood or "<EOS>"
            sure = f"; how sure: {choices_text(self.understood_choices)}" if self.understood_choices else ""
            lines.insert(1, f"I understood: {said} (the typed text said back with repeat language{sure})")
        if self.note:
            lines.insert(2, f"note: {self.note}")
        if self.acted_on is not None:
            lines.insert(2, f"acted on ({self.route}): {self.acted_on!r}")
        if self.rollout is not None:
            verdict = "the cube moved as told" if self.rollout.passed else f"failed ({self.rollout.check.reason})"
            held = self.signal in ("describe", "repeat language")
            lines.append(f"robot, {self.loop} loop: {verdict}" + ("; this signal asks for a pose, not an action"
                                                                   if held else ""))
        return "\n".join(lines)

    def figure(self) -> Figure:
        """Predicted joints against the target (left) and the GMU gate per dimension of h (right)."""
        fig, (left, right) = plt.subplots(1, 2, figsize=(10, 3.2), gridspec_kw={"width_ratios": [2, 1]})
        plot_joints(self.joints, self.target, title=f"{self.signal}: target is {TARGETS[self.signal]}", ax=left)
        right.bar(np.arange(len(self.gate)), self.gate, color=plt.cm.coolwarm(self.gate), width=1.0)
        right.axhline(self.gate.mean(), color="black", lw=1, ls=":")
        right.set(ylim=(0, 1), xlabel="dimension of h", ylabel="z (0 language, 1 action)",
                  title=f"GMU gate, mean {self.gate.mean():.2f}")
        fig.tight_layout()
        return fig

    def animation(self, every: int = 4, size: float = 3.0, dpi: int = 60):
        """The robot executing the joints, from NICO's eye, and its joints (a matplotlib animation), or None."""
        whole_number("every", every, 1), whole_number("dpi", dpi, 1)
        positive_number("size", size)
        if self.rollout is None:
            return None
        title = f"{textwrap.shorten(self.told, 36)}: {'done' if self.rollout.passed else 'failed'}"
        return animate_frames({"NICO's eye": self.rollout.frames}, joints=self.rollout.measured, every=every,
                              size=size, dpi=dpi, title=title)

    def displays(self, every: int = 4) -> list:
        """IPython display objects: the summary (HTML), the figure (PNG) and the animation (HTML)."""
        from IPython.display import HTML, Image

        fig = self.figure()
        png = io.BytesIO()
        fig.savefig(png, format="png", dpi=80)
        plt.close(fig)                                  # shown once, as the PNG, not again by the backend
        out = [HTML("<pre>" + html.escape(self.summary()) + "</pre>"), Image(data=png.getvalue(), format="png")]
        anim = self.animation(every)
        if anim is not None:
            out.append(HTML(anim.to_jshtml()))          # frames embedded as PNGs: plays offline
        return out

    def show(self, every: int = 4) -> None:
        """Display everything in a notebook."""
        from IPython.display import display

        display(*self.displays(every))


__all__ = ["EXPECTED", "TARGETS", "PlayResult", "choices_text", "word_choices"]
