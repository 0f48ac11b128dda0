"""Lab: a GRU in place of the LSTM in every encoder and decoder (not in the paper; its Sec. 3 uses peephole LSTMs).

A GRU (Cho et al. 2014) keeps one state h and three gate blocks where an LSTM has two states and four.
In PyTorch's form (``torch.nn.GRU``), blocks in the order r, z, n::

    r   = σ(x W_xr + b_xr + h_{t-1} W_hr + b_hr)            reset gate
    z   = σ(x W_xz + b_xz + h_{t-1} W_hz + b_hz)            update gate
    n   = tanh(x W_xn + b_xn + r ⊙ (h_{t-1} W_hn + b_hn))   candidate
    h_t = (1 − z) ⊙ n + z ⊙ h_{t-1}

A student's layer has the interface of the package's LSTMs (:mod:`pgae_lite.model.layers`): built as
``GRU(input_size, hidden_size, num_layers)``, with ``forward(x, lengths=None, state=None) -> (outputs, (h, c))``,
``step(x_t, state) -> (output, (h, c))`` and ``input_weight``. Having no cell state, it reads h from a state and
returns ``(h, h)``: the encoders' state vector [c; h] keeps its size. Per layer ``cells[l]`` holds ``weight_x``
(input, 3H), ``weight_h`` (H, 3H), ``bias_x`` and ``bias_h`` (3H), where :func:`check` copies its weights.
:func:`run` puts it in all four places (:func:`~pgae_lite.model.layers.recurrent_layers`) and trains it.
"""
from __future__ import annotations

import itertools
from typing import Callable

import torch
from torch import nn

from pgae_lite.course.labs.concat import train_at_budget
from pgae_lite.data.normaliser import Normaliser
from pgae_lite.data.toy import toy_dataset
from pgae_lite.exercises.result import RAISED, CheckResult, _build, _call, _compare, _diagnose, _pair
from pgae_lite.model.config import ModelConfig
from pgae_lite.model.layers import FusedLSTM, recurrent_layers
from pgae_lite.model.loss import pgae_loss
from pgae_lite.model.pgae import PGAE, count_parameters
from pgae_lite.model.signals import make_batch
from pgae_lite.util.checks import MAX_SEED, shown, whole_number
from pgae_lite.util.errors import ArgumentTypeError
from pgae_lite.world.words import DESCRIPTIONS, word_weights

TITLE = "A GRU in place of the LSTM"
STUDENT_NAME = "MyGRU"          # the student's component, in the lab's notebook
EPOCHS = 20     # the lab's budget: the GRU's seeds lie apart from the LSTM's on describe and execute (lab-gru.json)

EQUATION = ("r = σ(x W_xr + b_xr + h W_hr + b_hr), z = σ(x W_xz + b_xz + h W_hz + b_hz), "
            "n = tanh(x W_xn + b_xn + r ⊙ (h W_hn + b_hn)), h_t = (1 − z) ⊙ n + z ⊙ h")

FIGURES = {"describe": "describe: accuracy %", "execute_nrmse": "execute: joints nRMSE %",
           "parameters": "parameters of the model"}


class GRUCell(nn.Module):
    """One GRU layer, one time step (blocks r, z, n)."""

    def __init__(self, input_size: int, hidden_size: int):
        super().__init__()
        self.weight_x = nn.Parameter(torch.empty(input_size, 3 * hidden_size))
        self.weight_h = nn.Parameter(torch.empty(hidden_size, 3 * hidden_size))
        self.bias_x = nn.Parameter(torch.empty(3 * hidden_size))
        self.bias_h = nn.Parameter(torch.empty(3 * hidden_size))
        for p in self.parameters():
            nn.init.uniform_(p, -0.1, 0.1)                      # as the package's LSTMs

    def forward(self, gates_x: torch.Tensor, h: torch.Tensor) -> torch.Tensor:
        """``gates_x`` = x W_x + b_x (batch, 3H), precomputed for all steps at once; h (batch, H) -> h_t."""
        x_r, x_z, x_n = gates_x.chunk(3, dim=1)                 # each (batch, H)
        h_r, h_z, h_n = (h @ self.weight_h + self.bias_h).chunk(3, dim=1)
        r = torch.sigmoid(x_r + h_r)                            # r = σ(x W_xr + b_xr + h W_hr + b_hr)
        z = torch.sigmoid(x_z + h_z)                            # z = σ(x W_xz + b_xz + h W_hz + b_hz)
        n = torch.tanh(x_n + r * h_n)                           # n = tanh(x W_xn + b_xn + r ⊙ (h W_hn + b_hn))
        return (1 - z) * n + z * h                              # h_t = (1 − z) ⊙ n + z ⊙ h_{t-1}


class GRU(nn.Module):
    """A stack of GRU layers over a batch-first sequence, with the interface of the package's LSTMs."""

    Cell = GRUCell

    def __init__(self, input_size: int, hidden_size: int, num_layers: int = 2):
        super().__init__()
        self.hidden_size, self.num_layers = hidden_size, num_layers
        self.cells = nn.ModuleList(self.Cell(input_size if layer == 0 else hidden_size, hidden_size)
                                   for layer in range(num_layers))

    @property
    def input_weight(self) -> nn.Parameter:
        """First layer's input weights (input, 3H): for one-hot inputs, a word embedding."""
        return self.cells[0].weight_x

    def forward(self, x: torch.Tensor, lengths: torch.Tensor | None = None,
                state: tuple[torch.Tensor, torch.Tensor] | None = None):
        """x (batch, T, input) -> outputs (batch, T, H) and the final (h, h); h frozen past a sample's length."""
        batch, steps, _ = x.shape
        h0 = x.new_zeros(self.num_layers, batch, self.hidden_size) if state is None else state[0]  # c: none
        valid = None
        if lengths is not None:  # (T, batch, 1) True where step t is inside the sequence
            valid = (torch.arange(steps, device=x.device)[:, None] < lengths.to(x.device)[None, :])[..., None]
        layer_in, hs = x, []
        for layer, cell in enumerate(self.cells):
            gates_x = (layer_in @ cell.weight_x + cell.bias_x).unbind(1)    # T x (batch, 3H)
            h, outs = h0[layer], []
            for t in range(steps):
                h_new = cell(gates_x[t], h)
                h = h_new if valid is None else torch.where(valid[t], h_new, h)
                outs.append(h)
            layer_in = torch.stack(outs, 1)                     # (batch, T, H)
            hs.append(h)
        h = torch.stack(hs)                                     # (layers, batch, H)
        return layer_in, (h, h)

    def step(self, x_t: torch.Tensor, state: tuple[torch.Tensor, torch.Tensor]):
        """One time step for all layers: x_t (batch, input) -> output (batch, H), new state (h, h)."""
        hs, inp = [], x_t
        for layer, cell in enumerate(self.cells):
            inp = cell(inp @ cell.weight_x + cell.bias_x, state[0][layer])
            hs.append(inp)
        h = torch.stack(hs)
        return inp, (h, h)


BASELINE = FusedLSTM        # the book's cell: torch.nn.LSTM behind the package's interface
REFERENCE = GRU


# ------------------------------------------------------------------ the run
def run(component: Callable[[int, int, int], nn.Module], seed: int = 0, profile=None,
        progress: bool = False) -> dict[str, float]:
    """PGAE with ``component(input_size, hidden_size, num_layers)`` as every recurrent layer, trained for
    ``EPOCHS`` epochs: describe's accuracy, execute's nRMSE (%) and the model's parameters."""
    if not callable(component):
        raise ArgumentTypeError("component must be a class or function that builds the recurrent layer, "
                                f"component(input_size, hidden_size, num_layers); got {shown(component)}")

    def build(profile) -> nn.Module:
        with recurrent_layers(component):
            return PGAE(profile.model, profile.data.the_world.lexicon)

    trained, cells = train_at_budget(build, seed, profile, EPOCHS, progress, TITLE)
    return {"describe": cells["describe"]["accuracy"], "execute_nrmse": cells["execute"]["nrmse"],
            "parameters": float(count_parameters(trained.model))}


# ------------------------------------------------------------------ the check
def _equations(x, h, cells: dict, order="rzn", swap_z=False, reset_before=False, tanh_n=True, bias_h=True):
    """One step of every layer by the equations, with switches that reproduce common mistakes; the new h."""
    hs, inp = [], x
    for layer, h_l in enumerate(h):
        w = {k: cells[f"cells.{layer}.{k}"] for k in ("weight_x", "weight_h", "bias_x", "bias_h")}
        gx = dict(zip(order, (inp @ w["weight_x"] + w["bias_x"]).chunk(3, dim=1)))      # x W_x + b_x, per block
        wh = dict(zip(order, w["weight_h"].chunk(3, dim=1)))
        bh = dict(zip(order, w["bias_h"].chunk(3) if bias_h else (0, 0, 0)))
        r, z = (torch.sigmoid(gx[g] + h_l @ wh[g] + bh[g]) for g in "rz")
        n = gx["n"] + ((r * h_l) @ wh["n"] + bh["n"] if reset_before else r * (h_l @ wh["n"] + bh["n"]))
        n = torch.tanh(n) if tanh_n else n
        inp = z * n + (1 - z) * h_l if swap_z else (1 - z) * n + z * h_l        # h_t = (1 − z) ⊙ n + z ⊙ h
        hs.append(inp)
    return torch.stack(hs)


def _mistakes(x, h, c, cells: dict) -> list[tuple[str, tuple]]:
    variant = lambda **k: _equations(x, h, cells, **k)      # noqa: E731 - a mistake's new h
    mistakes = [("z and 1 − z swapped: h_t = (1 − z) ⊙ n + z ⊙ h_{t-1}", variant(swap_z=True)),
                ("your reset gate acts before the product, (r ⊙ h) W_hn (Cho et al.'s first form); this lab, as "
                 "torch.nn.GRU, resets after it: r ⊙ (h W_hn + b_hn)", variant(reset_before=True)),
                ("n needs a tanh: n = tanh(x W_xn + b_xn + r ⊙ (h W_hn + b_hn))", variant(tanh_n=False)),
                ("the hidden bias b_h is missing", variant(bias_h=False)),
                ("you read c from the state; a GRU has only h: state[0]", _equations(x, c, cells))]
    mistakes += [(f"you split the blocks in the order {', '.join(order)}; the lab's order is r, z, n "
                  "(torch.nn.GRU's)", variant(order="".join(order)))
                 for order in itertools.permutations("rzn") if order != tuple("rzn")]
    return [(words, (new,)) for words, new in mistakes]


def _state(result: CheckResult, out, who: str, shape: tuple) -> torch.Tensor | None:
    """h of ``out`` = (output, (h, c)), or None after a failure line; c must be h."""
    if not _pair(result, out, "output, (h, c)", who, shape):
        return None
    state = out[1]
    if not isinstance(state, (tuple, list)) or len(state) != 2 or \
            not all(isinstance(t, torch.Tensor) and t.shape == shape for t in state):
        result.fail(f"{who} returned the state {shown(state)}; expected (h, c), each (layers, batch, H) = {shape}",
                    "a GRU has no cell state: return (h, h)")
        return None
    if not torch.equal(state[0], state[1]):
        result.fail(f"{who} returned a c that is not h", "a GRU has no cell state: return (h, h), so that the "
                    "encoders' state vector [c; h] keeps its size")
    return state[0]


@torch.random.fork_rng(devices=[])                     # the student's global random state stays as it was
def check(component: Callable[[int, int, int], nn.Module], seed: int = 0) -> CheckResult:
    """Is ``component`` a GRU layer for PGAE? Its structure (three gate blocks, the lab's parameter names and
    count), its step against the equations, its sequences (lengths, a given state) and its place in a small PGAE."""
    seed = whole_number("seed", seed, 0, MAX_SEED)
    result, gen = CheckResult("GRU layer for PGAE"), torch.Generator().manual_seed(seed)
    torch.manual_seed(seed)
    layer, ref = _build(result, component, 3, 4, 2), GRU(3, 4, 2)    # input 3, H 4, 2 layers
    if layer is not None and _structure(result, layer, ref):
        with torch.no_grad():   # U(-1, 1), not U(-0.1, 0.1): every term of the equations then shows
            for p in ref.parameters():
                p.copy_(torch.rand(p.shape, generator=gen) * 2 - 1)
            layer.load_state_dict(ref.state_dict())
            _behaviour(result, layer, ref.state_dict(), gen)
    if layer is not None and _in_pgae(result, component, seed):
        counts = [count_parameters(_pgae(factory, ModelConfig())) for factory in (component, FusedLSTM)]
        result.note(f"parameters of the book's PGAE: {counts[0]:,} with your layer, {counts[1]:,} with the LSTM")
    return result


def _structure(result: CheckResult, layer: nn.Module, ref: GRU) -> bool:
    """The lab's parameters (three gate blocks per layer) and ``input_weight``; whether the weights can be copied."""
    got = _call(result, "listing your layer's parameters",
                lambda: {k: tuple(v.shape) for k, v in layer.state_dict().items()})
    if got is RAISED:
        return False
    expected = {k: tuple(v.shape) for k, v in ref.state_dict().items()}
    count, gru, lstm = (sum(torch.Size(s).numel() for s in got.values()), count_parameters(ref),
                        count_parameters(nn.LSTM(3, 4, 2)))
    if got != expected:
        blocks = " (four gate blocks per layer: an LSTM's; a GRU has three, r, z and n)" if count == lstm else ""
        return result.fail(f"{count} parameters{blocks}, named {got}; the lab's GRU of 2 layers has {gru}: "
                           f"{expected}", "per layer, cells[l] holds weight_x (input, 3H), weight_h (H, 3H), bias_x "
                           "and bias_h (3H): three gate blocks in the order r, z, n").passed
    result.ok(f"{count} parameters in three gate blocks per layer, as the lab's GRU (an nn.LSTM has {lstm})")
    weight = _call(result, "your input_weight", lambda: layer.input_weight)
    if weight is not RAISED and weight is not layer.get_parameter("cells.0.weight_x"):
        result.fail(f"input_weight is {shown(weight)}; expected the first layer's input weights, cells[0].weight_x",
                    "the language encoder and decoder initialise it as a word embedding: a @property returning it")
    return result.passed


def _behaviour(result: CheckResult, layer: nn.Module, cells: dict, gen: torch.Generator) -> None:
    """One step against the equations, then sequences: with lengths (each sample's final state after its last
    valid step), without, and from a given state."""
    B, T, D, L, H = 5, 6, 3, 2, 4                          # batch, steps, input, layers, units
    x, h, c = (torch.rand(*shape, generator=gen) * 2 - 1 for shape in ((B, D), (L, B, H), (L, B, H)))
    new = _state(result, _call(result, "your step", layer.step, x.clone(), (h.clone(), c.clone())), "your step",
                 (L, B, H))
    if new is not None and not _compare(result, "the step's new h", new, _equations(x, h, cells)):
        _diagnose(result, (new,), _mistakes(x, h, c, cells), EQUATION)
    if not result:
        return
    xs, lengths = torch.rand(B, T, D, generator=gen) * 2 - 1, torch.tensor([T, 3, 1, T, 4])
    for name, given_lengths, h0 in (("with lengths", lengths, None), ("without lengths", None, None),
                                    ("from a given state", lengths, h)):
        start = torch.zeros(L, B, H) if h0 is None else h0
        seen = torch.full((B,), T) if given_lengths is None else given_lengths
        state, outputs = start, []
        for t in range(T):                                  # the reference: each sample frozen past its length
            state = torch.where((t < seen)[None, :, None], _equations(xs[:, t], state, cells), state)
            outputs.append(state[-1])
        out = _call(result, f"your forward {name}", layer, xs.clone(), given_lengths,
                    None if h0 is None else (h.clone(), c.clone()))
        final = _state(result, out, f"your forward {name}", (L, B, H))
        if final is None:
            return
        ys, expected = out[0], torch.stack(outputs, 1)      # (B, T, H)
        if isinstance(ys, torch.Tensor) and ys.shape == expected.shape:     # past a sample's length: anything
            ys = torch.where((torch.arange(T)[None, :] < seen[:, None])[..., None], ys, expected)
        _compare(result, f"outputs {name}, inside each sample's length", ys, expected)
        if not _compare(result, f"final h {name}", final, state) and given_lengths is not None:
            everything = start
            for t in range(T):
                everything = _equations(xs[:, t], everything, cells)
            if torch.allclose(final, everything, atol=1e-5):
                result.note("the shorter samples' final h is the one after all T steps: freeze h past a sample's "
                            "length, h = torch.where(valid[t], h_new, h), as the package's PeepholeLSTM does")


def _pgae(factory, cfg: ModelConfig) -> PGAE:
    with recurrent_layers(factory):
        return PGAE(cfg)


def _in_pgae(result: CheckResult, factory, seed: int) -> bool:
    """A small PGAE with the layer in its encoders and decoders: forward (sequences with lengths and a given
    state, steps) and backward, the gradient reaching every recurrent parameter."""
    toy = toy_dataset(1, seed, patterns=[0, 7, 80, 101, 140])  # five recordings, 100 or 50 steps
    batch = make_batch(Normaliser.fit(toy).tensors(toy), torch.arange(5), signal=torch.arange(5),  # one each
                       alternative=torch.arange(5) % DESCRIPTIONS)
    for feedback, teacher in (("start", False), ("predicted", True)):
        torch.manual_seed(seed)
        cfg = ModelConfig(units=8, layers=2, hidden=6, joint_feedback=feedback)
        model = _call(result, "building a small PGAE with your layer", _pgae, factory, cfg)
        out = RAISED if model is RAISED else _call(result, f"its forward (joint feedback {feedback!r})", model,
                                                   batch, teacher)
        if out is RAISED:
            return False
        loss = pgae_loss(out, batch, word_weights())[0]
        if not torch.isfinite(loss) or _call(result, "the backward pass", loss.backward) is RAISED:
            return result.fail(f"the loss is {loss.item()}", "does your layer give NaN or inf?").passed
        rnns = {part: getattr(model, part).rnn for part in ("language_encoder", "action_encoder",
                                                            "language_decoder", "action_decoder")}
        dead = [f"{part}.rnn.{n}" for part, rnn in rnns.items() for n, p in rnn.named_parameters()
                if p.grad is None or not p.grad.any()]
        if dead:
            return result.fail(f"no gradient reaches {', '.join(dead)}", "is every parameter used?").passed
    result.ok("in a small PGAE (both joint feedbacks, the decoders' steps and sequences): forward and backward, "
              "the gradient reaching every parameter of its four layers")
    return True


# ------------------------------------------------------------------ deliberate mistakes (CI runs them)
class _MistakenCell(GRUCell):
    """The step with a mistake: ``swap_z`` (z and 1 − z swapped) or ``reset_before`` ((r ⊙ h) W_hn)."""
    swap_z = reset_before = False

    def forward(self, gates_x, h):
        (x_r, x_z, x_n), (w_r, w_z, w_n) = gates_x.chunk(3, dim=1), self.weight_h.chunk(3, dim=1)
        b_r, b_z, b_n = self.bias_h.chunk(3)
        r, z = torch.sigmoid(x_r + h @ w_r + b_r), torch.sigmoid(x_z + h @ w_z + b_z)
        n = torch.tanh(x_n + ((r * h) @ w_n + b_n if self.reset_before else r * (h @ w_n + b_n)))
        return z * n + (1 - z) * h if self.swap_z else (1 - z) * n + z * h


class SwappedUpdate(GRU):
    """h_t = z ⊙ n + (1 − z) ⊙ h_{t-1}: the update gate's weights swapped."""
    Cell = type("SwappedCell", (_MistakenCell,), {"swap_z": True})


class ResetBefore(GRU):
    """n = tanh(x W_xn + b_xn + (r ⊙ h) W_hn + b_hn): the reset applied before the product (Cho et al.'s form)."""
    Cell = type("ResetBeforeCell", (_MistakenCell,), {"reset_before": True})


class IgnoresLengths(GRU):
    """Every sample runs all T steps: its final state is not the one after its last valid step."""

    def forward(self, x, lengths=None, state=None):
        return super().forward(x, None, state)


class ZeroCell(GRU):
    """Its sequences return (h, 0) for the state: half of the encoders' state vector [c; h] is zeros."""

    def forward(self, x, lengths=None, state=None):
        y, (h, _) = super().forward(x, lengths, state)
        return y, (h, torch.zeros_like(h))


WRONG = {
    "the update gate's weights swapped": (SwappedUpdate, ["z and 1 − z swapped"]),
    "the reset before the product": (ResetBefore, ["your reset gate acts before the product"]),
    "the lengths ignored": (IgnoresLengths, ["freeze h past a sample's length"]),
    "zeros for c": (ZeroCell, ["a c that is not h", "return (h, h)"]),
}

__all__ = ["BASELINE", "EPOCHS", "FIGURES", "GRU", "GRUCell", "REFERENCE", "STUDENT_NAME", "TITLE", "WRONG", "check",
           "run"]
