"""The playground: choose a task, an episode or a sentence, and see what PGAE does.

Paper, Sec. 3 ("Signals") and Sec. 4 (Table 1's tasks). One model does every
task; the signal at the start of its language input picks which. :func:`play`
runs one signal on one recorded episode of our simulator and keeps all there is
to see:

    episode = the recording of (arrangement, action), or of the description typed
    batch   = make_batch(episode, signal, words)           what the task reads (signals.py)
    out     = model(batch)                                 generated words, joints, GMU gate z
    rollout = the simulator executes the predicted joints  (closedloop.open_loop / closed_loop)

Text. Under ``execute`` and ``repeat language`` the model reads the words: a
typed description (``action colour speed``, any synonym) replaces the
episode's and picks the episode itself, the action it names in the chosen
arrangement. PGAE's LSTM reads only those 22 words; PGAE-BERT's transformer
reads any text (paper, Sec. 3), then the chosen action is the one meant. Free text the robot
will not act on under ``execute`` (a negation, more than one instruction, a cube not on the
table: :mod:`pgae_lite.freeform.refusals`) is refused with the reason; where the model's readback
and the chosen action disagree, the result's ``note`` says so.
Under ``describe`` and ``repeat action`` the model reads no words, and a typed
description only picks the episode. Bad text raises a
:class:`~pgae_lite.world.words.LanguageError` that says what is wrong.

:class:`Playground` is the ipywidgets front end: it only collects the choices,
calls :func:`play` and shows the result, or the error's message.
"""
from __future__ import annotations

import html
from typing import Mapping

import numpy as np
import torch

from pgae_lite.bert.pretrained import input_text
from pgae_lite.cae import ChannelSeparatedCAE
from pgae_lite.config import PROFILES
from pgae_lite.data.dataset import PGAEDataset, description_text
from pgae_lite.data.normaliser import Normaliser
from pgae_lite.freeform.refusals import check_instruction, disagreement
from pgae_lite.model.pgae import PGAE
from pgae_lite.model.signals import LANG_IN, LANG_OUT, make_batch, signal_ids
from pgae_lite.robot.closedloop import closed_loop, open_loop, pattern_for
from pgae_lite.robot.instructions import acted_on, check_route
from pgae_lite.robot.play_result import TARGETS, PlayResult, word_choices
from pgae_lite.robot.playground_checks import (
    LAST_PATTERN,
    action_number,
    arrangement_number,
    check_objects,
    check_playground,
)
from pgae_lite.robot.typed_text import read_typed
from pgae_lite.sim.dataset import DatasetConfig
from pgae_lite.util.checks import instance_of, whole_number
from pgae_lite.util.errors import PGAELiteError
from pgae_lite.world import patterns
from pgae_lite.world.patterns import ACTION_SIDES, ARRANGEMENTS, Pattern, pattern_parts
from pgae_lite.world.typed import normalise_typed
from pgae_lite.world.words import (
    SIGNALS,
    VOCABULARY,
    WORD_INDEX,
    decode,
    is_correct,
    normalise_signal,
)

#: The signals the reader chooses from (``repeat both`` is for training only, but :func:`play` takes it).
PLAY_SIGNALS: tuple[str, ...] = ("describe", "execute", "repeat action", "repeat language")
#: What the "act on" menu calls each route of free text under execute (:mod:`pgae_lite.robot.instructions`).
ROUTE_LABELS: dict[str, str] = {"said back": "what it said back", "direct": "the sentence"}
#: The signal under which free text takes a route: the robot acts.
ROUTE_SIGNAL = "execute"
#: The 12 actions of an arrangement, (action, cube side, speed);
#: action k is pattern 72·(k // 6) + 6·arrangement + k % 6.
ACTIONS: tuple[tuple[str, str, str], ...] = tuple((a, side, speed) for speed in ("slowly", "fast")
                                                  for a, side in ACTION_SIDES)
def arrangement_label(arrangement: int) -> str:
    """E.g. ``"red left, blue right"`` for arrangement 0."""
    left, right = ARRANGEMENTS[arrangement_number(arrangement)]
    return f"{left} left, {right} right"


def action_label(action: int) -> str:
    """E.g. ``"push the left cube, slowly"`` for action 0."""
    act, side, speed = ACTIONS[action_number(action)]
    return f"{act} the {'left' if side == 'L' else 'right'} cube, {speed}"


def scene_pattern(arrangement: int, action: int) -> int:
    """The pattern (0-143) of action ``action`` (0-11) in arrangement ``arrangement`` (0-11)."""
    arrangement, action = arrangement_number(arrangement), action_number(action)
    return patterns.pattern_number(action // 6, arrangement, action % 6)


def simulator_config(data: PGAEDataset) -> DatasetConfig:
    """The simulated dataset's config (found by the key in ``data.source``), else the book profile's."""
    instance_of("data", data, PGAEDataset, "a PGAEDataset")
    key = str(data.source).rpartition(":")[2]
    return next((p.data for p in PROFILES.values() if p.data.key() == key), PROFILES["book"].data)


#: find_episode's messages (the page says them too: pgae_lite.web.messages). ``where``: "this dataset".
MESSAGES = {
    "no_recording": "{where} has no recording of {what}; its arrangements are: {arrangements}",
    "no_variation": "{where} has {count} recording(s) of {what}, so no variation {variation} (count from 0)",
    "pattern_named": "pattern {pattern} ({action} {colour} {speed}, {left} left, {right} right)",
    "this_dataset": "this dataset",
}


def find_episode(data: PGAEDataset, pattern: int, variation: int = 0) -> tuple[int, int]:
    """(row in ``data``, simulator variation) of the ``variation``-th recording of ``pattern``."""
    instance_of("data", data, PGAEDataset, "a PGAEDataset")
    pattern = whole_number("pattern", pattern, 0, LAST_PATTERN)
    variation = whole_number("variation", variation, 0)
    rows = np.flatnonzero(data.pattern == pattern)
    if variation >= len(rows):
        p = Pattern.from_number(pattern)
        have = sorted({arrangement_label(pattern_parts(int(q))[1]) for q in data.pattern})
        what = MESSAGES["pattern_named"].format(pattern=pattern, action=p.action, colour=p.colour, speed=p.speed,
                                                left=p.left, right=p.right)
        where = MESSAGES["this_dataset"]
        raise ValueError(MESSAGES["no_recording"].format(where=where, what=what, arrangements="; ".join(have))
                         if not len(rows) else MESSAGES["no_variation"].format(
                             where=where, count=len(rows), what=what, variation=variation))
    row = int(rows[variation])
    name = str(data.ids[row])                                   # "sim/PPP-V" for our simulator's episodes
    return row, int(name.rsplit("-", 1)[1]) if name.startswith("sim/") else variation


@torch.no_grad()
def play(model: PGAE, cae: ChannelSeparatedCAE | None, normaliser: Normaliser, data: PGAEDataset,
         signal: str = "execute", arrangement: int = 0, action: int = 0, text: str | None = None, *,
         variation: int = 0, loop: str | None = "open", config: DatasetConfig | None = None,
         route: str = "direct") -> PlayResult:
    """Run ``model`` with one signal on the recorded episode of (``arrangement``, ``action``), or of ``text``.

    ``text``: a description, or with PGAE-BERT any instruction (see the module
    docstring). ``loop``: how the simulator executes the predicted joints:
    ``"open"`` (:func:`~pgae_lite.robot.closedloop.open_loop`), ``"closed"`` (execute
    only: :func:`~pgae_lite.robot.closedloop.closed_loop`, which needs ``cae``) or
    None (no simulation). ``config``: the simulated dataset's (default: found
    from ``data``). ``route``: free text under ``execute`` is executed ``"direct"``
    or ``"said back"`` (its readback's words: :mod:`pgae_lite.robot.instructions`). Raises
    LanguageError or ValueError (a TypeError for a wrong type), with a readable message, for a bad
    signal, text, choice or object. A typed text is parsed once (:func:`~pgae_lite.robot.typed_text.read_typed`).
    """
    check_objects(model, cae, normaliser, data, config)
    scene_pattern(arrangement, action)                    # checks both
    instance_of("text", text, str, "a description (a string)", optional=True)
    signal, text = normalise_signal(signal), normalise_typed(text or "").strip()   # as typed, read once (typed.py)
    check_route(route)
    if loop not in ("open", "closed", None):
        raise ValueError(f"unknown loop {loop!r}; the options are: 'open', 'closed', None")
    if loop == "closed" and (signal != "execute" or cae is None):
        raise ValueError("the closed loop runs the signal execute, with the CAE: the model writes each step's "
                         "joints from what its camera sees (choose execute, or the open loop)")
    typed = read_typed(model.language_encoder, signal, text) if text else None   # parsed once, here
    words = typed.words if typed else None
    pattern = pattern_for(typed.meaning, arrangement) if words else scene_pattern(arrangement, action)
    row, sim_variation = find_episode(data, pattern, variation)
    device = next(model.parameters()).device
    tensors = normaliser.tensors(data.subset([row]), device)
    if words:                                              # the reader's words replace the episode's
        tensors["descriptions"][:] = torch.tensor([WORD_INDEX[w] for w in words], device=device)
    said = text or description_text(tensors["descriptions"][0, 0].cpu().numpy())   # the words the task may read
    reads_words = LANG_IN[SIGNALS.index(signal)]
    told = input_text(signal, (typed.read if typed else said) if reads_words else "")   # as the model reads it
    free = bool(reads_words and typed and typed.is_free)   # a pretrained encoder reads the text as it is

    model.eval()
    zero = torch.zeros(1, dtype=torch.long)
    understood = understood_choices = acted = None
    if reads_words and text:                               # readback: the same words, said back, no action shown
        back_language = typed.features("repeat language") if free else None
        back = model(make_batch(tensors, zero, signal_ids("repeat language", 1), zero), language=back_language)
        understood = decode(back["logits"][0].argmax(-1).cpu())
        understood_choices = word_choices(back["logits"][0])
    note = None
    if free and signal == "execute":                      # the robot acts: first, whether it can (refusals.py)
        scene = Pattern.from_number(pattern)
        check_instruction(text, model.language_encoder, (scene.left, scene.right), understood)
        note = disagreement(understood, pattern)
    language = None
    routed = route if free and signal == ROUTE_SIGNAL else None   # the route free text takes under execute
    if routed == "said back":                              # act on its own words
        said = acted = acted_on([understood], [said])[0]
        told = input_text(signal, said)
        language = model.language_encoder.encode_texts([told])
    elif free:
        language = typed.features(signal)                  # encoded once: also what the closed loop reads
    batch = make_batch(tensors, zero, signal_ids(signal, 1), zero)
    out = model(batch, language=language)
    length = int(data.lengths[row])
    joints = normaliser.joints_to_data(torch.cat([batch.start_joints[:, None], out["joints"]], 1))[0, :length]
    target = normaliser.joints_to_data(torch.cat([batch.start_joints[:, None], batch.joint_target], 1))[0, :length]
    joints, target = joints.cpu().numpy(), target.cpu().numpy()
    generated = decode(out["logits"][0].argmax(-1).cpu())
    expected = [tuple(VOCABULARY[w] for w in alt) for alt in Pattern.from_number(pattern).descriptions()]

    config = config or simulator_config(data)
    rollout = None
    if loop == "open":
        rollout = open_loop(joints, pattern, sim_variation, description=told, config=config, render=True)
    elif loop == "closed":
        rollout = closed_loop(model, cae, normaliser, pattern, sim_variation, said, config=config,
                              language=language, steps=length)
        joints = rollout.joints
    nrmse = 100 * float(np.sqrt(np.mean((joints[1:] - target[1:]) ** 2))) / data.joint_range()
    return PlayResult(signal, pattern, sim_variation, str(data.ids[row]), told, generated,
                      is_correct(generated, expected if LANG_OUT[SIGNALS.index(signal)] else None),
                      joints, target, nrmse, out["gate"][0].cpu().numpy(), rollout, loop, understood, note,
                      word_choices(out["logits"][0]), understood_choices, routed, acted)


class Playground:
    """ipywidgets front end of :func:`play`: choose, press Run, see the result (or what was wrong).

    ``models`` maps a name to ``(model, normaliser)``, e.g.
    ``{"PGAE": (pgae.model, pgae.normaliser)}``. The last result is kept in
    ``self.result``, the last error message in ``self.message``; the widgets
    are attributes (``signal``, ``arrangement``, ``action``, ``text``, ``button``,
    ``output``...), so a test can set them and call ``button.click()``.
    ``signal``, ``arrangement`` and ``action`` are the first choices shown. ``routes``: each model's
    route for free text under execute (:func:`~pgae_lite.robot.instructions.default_route` of its recipe),
    the "act on" menu's choice when that model is picked ("direct" for a model not named); without
    ``routes`` the menu starts at "said back" and stays where the reader puts it.
    """

    def __init__(self, models: Mapping[str, tuple[PGAE, Normaliser]], cae: ChannelSeparatedCAE | None,
                 data: PGAEDataset, *, config: DatasetConfig | None = None, every: int = 4,
                 signal: str = "execute", arrangement: int | None = None, action: int = 0,
                 routes: Mapping[str, str | None] | None = None):
        import ipywidgets as w

        check_playground(models, cae, data, config, every, signal, arrangement, action,
                         PLAY_SIGNALS)
        self.models, self.cae, self.data, self.config, self.every = dict(models), cae, data, config, every
        self.result: PlayResult | None = None
        self.message = ""
        arrangements = sorted({pattern_parts(int(p))[1] for p in data.pattern})   # those the dataset recorded
        variations = int(np.bincount(data.pattern).max())
        self.model = w.Dropdown(options=list(self.models), description="model")
        self.signal = w.ToggleButtons(options=PLAY_SIGNALS, value=normalise_signal(signal), description="signal")
        self.arrangement = w.Dropdown(options=[(arrangement_label(a), a) for a in arrangements],
                                      value=arrangements[0] if arrangement is None else arrangement,
                                      description="cubes")
        self.action = w.Dropdown(options=[(action_label(k), k) for k in range(len(ACTIONS))], value=action,
                                 description="action")
        self.variation = w.Dropdown(options=list(range(variations)), description="variation")
        self.text = w.Text(description="or say", placeholder="e.g. push red slowly (PGAE-BERT: any sentence)",
                           layout=w.Layout(width="32em"))
        self.loop = w.Dropdown(options=[("open loop", "open"), ("closed loop (execute)", "closed"), ("no robot", None)],
                               description="robot")
        self.route = w.Dropdown(options=[(label, route) for route, label in ROUTE_LABELS.items()],
                                description="act on")            # free text under execute (PGAE-BERT)
        self.routes = dict(routes or {})
        for route in self.routes.values():
            if route is not None:
                check_route(route)

        def follow(_change=None):                                # the model's own route when it is picked
            self.route.value = self.routes.get(self.model.value) or "direct"
        if routes is not None:
            self.model.observe(follow, names="value")
            follow()
        self.button = w.Button(description="Run", button_style="primary", icon="play")
        self.output = w.Output()
        self.button.on_click(self.run)
        self.widget = w.VBox([w.HBox([self.model, self.loop]), self.signal, w.HBox([self.arrangement, self.action]),
                              w.HBox([self.text, self.variation]), self.route, self.button, self.output])

    def run(self, _button=None) -> None:
        """Call :func:`play` with the widgets' values and put what it made (or the error) in ``output``."""
        from IPython.display import HTML

        self.output.outputs = ()                           # works with and without a kernel
        self.result, self.message = None, ""
        self.button.disabled, self.button.description = True, "Running..."
        model, normaliser = self.models[self.model.value]
        try:
            self.result = play(model, self.cae, normaliser, self.data, self.signal.value, self.arrangement.value,
                               self.action.value, self.text.value, variation=self.variation.value,
                               loop=self.loop.value, config=self.config, route=self.route.value)
            shown = self.result.displays(self.every)
        except (ValueError, PGAELiteError) as e:   # the reader's choice, not a bug
            self.message = str(e)
            shown = [HTML(f'<p style="color:#a40000"><b>Cannot run this:</b> {html.escape(self.message)}</p>')]
        finally:
            self.button.disabled, self.button.description = False, "Run"
        for item in shown:
            self.output.append_display_data(item)

    def _repr_mimebundle_(self, **kwargs):
        return self.widget._repr_mimebundle_(**kwargs)


__all__ = [
    "ACTIONS", "PLAY_SIGNALS", "ROUTE_LABELS", "ROUTE_SIGNAL", "TARGETS", "PlayResult", "Playground",
    "action_label", "arrangement_label", "find_episode", "scene_pattern", "play", "simulator_config"]
