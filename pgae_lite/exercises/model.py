"""Checks of the model chapter's exercises: the LSTM step, the GMU or a replacement, the signals.

Paper, Sec. 3 (the peephole LSTM of the encoders and decoders, the GMU
"Bottleneck", the signals and how often training draws each). Each check runs
a student's code next to the reference on seeded random inputs and returns a
:class:`~pgae_lite.exercises.result.CheckResult` that names a known mistake
when one reproduces the student's outputs (chapter 04; ``check_bottleneck``
also in chapter 05).
"""
from __future__ import annotations

import copy
import itertools
import math
import re
from functools import partial
from typing import Callable, Sequence

import torch
from torch import nn

from pgae_lite.data.normaliser import Normaliser
from pgae_lite.data.toy import toy_dataset
from pgae_lite.exercises.result import (
    RAISED,
    CheckResult,
    _build,
    _call,
    _compare,
    _diagnose,
    _numbers,
    _pair,
    _shape,
    _unchanged,
    _value_problem,
)
from pgae_lite.model.config import ModelConfig
from pgae_lite.model.layers import GatedMultimodalUnit, PeepholeLSTMCell
from pgae_lite.model.loss import pgae_loss
from pgae_lite.model.pgae import PGAE, count_parameters
from pgae_lite.model.signals import SIGNAL_PROBS, make_batch, sample_signals
from pgae_lite.util.checks import MAX_SEED, whole_number
from pgae_lite.world.words import DESCRIPTIONS, SIGNALS, word_weights

LSTM_EQUATION = ("[i; j; f; o] = x W_x + h W_h + b, c_t = σ(f + 0.8 + p_f ⊙ c_{t-1}) ⊙ c_{t-1} "
                 "+ σ(i + p_i ⊙ c_{t-1}) ⊙ tanh(j), h_t = σ(o + p_o ⊙ c_t) ⊙ tanh(c_t)")
GMU_EQUATION = ("A_h = tanh(W_A f_act + b), L_h = tanh(W_L f_lang + b), z = σ(W_z [f_act; f_lang] + b), "
                "h = z*A_h + (1-z)*L_h")


# ------------------------------------------------------------------ the LSTM step: (a) and (d)
def _step(x, h, c, cell, order="ijfo", forget_bias=0.8, peepholes=True, tanh_j=True, tanh_c=True, o_new_c=True):
    """:class:`~pgae_lite.model.layers.PeepholeLSTMCell`'s step, with switches that reproduce common mistakes."""
    g = dict(zip(order, (x @ cell.weight_x + h @ cell.weight_h + cell.bias).chunk(4, dim=1)))
    p_i, p_f, p_o = (cell.peep_i, cell.peep_f, cell.peep_o) if peepholes else (0.0, 0.0, 0.0)
    c_new = (torch.sigmoid(g["f"] + forget_bias + p_f * c) * c
             + torch.sigmoid(g["i"] + p_i * c) * (torch.tanh(g["j"]) if tanh_j else g["j"]))
    h_new = torch.sigmoid(g["o"] + p_o * (c_new if o_new_c else c)) * (torch.tanh(c_new) if tanh_c else c_new)
    return h_new, c_new


@torch.random.fork_rng(devices=[])  # every check leaves the student's global random state alone
def _check_step(student: Callable, peepholes: bool, name: str, seed: int) -> CheckResult:
    result, gen = CheckResult(name), torch.Generator().manual_seed(whole_number("seed", seed, 0, MAX_SEED))
    cell = PeepholeLSTMCell(3, 4)
    with torch.no_grad():  # U(-1, 1), not U(-0.1, 0.1): every term of the equation then shows
        for p in cell.parameters():
            p.copy_(torch.rand(p.shape, generator=gen) * 2 - 1)
    x, h, c = (torch.rand(5, n, generator=gen) * 2 - 1 for n in (3, 4, 4))
    result.note(f"inputs: x {tuple(x.shape)}, h and c {tuple(h.shape)}, cell = PeepholeLSTMCell(3, 4)")
    variant = partial(_step, x, h, c, cell, peepholes=peepholes)      # the reference, or a mistake
    ref = variant()
    given = {"x": x.clone(), "h": h.clone(), "c": c.clone()}  # the student sees copies
    given_cell = copy.deepcopy(cell)
    state = (given["h"], given["c"])
    out = _call(result, "your step", student, given["x"], state, given_cell)
    if not _pair(result, out, "h, c", "your step", tuple(h.shape)):
        return result
    weights = {f"cell.{n}": p for n, p in cell.named_parameters()}
    given.update((f"cell.{n}", p) for n, p in given_cell.named_parameters())
    _unchanged(result, "your step", given, {"x": x, "h": h, "c": c, **weights})
    if all([_compare(result, n, g, e) for n, g, e in zip(("h_t", "c_t"), out, ref)]):
        if not peepholes:
            result.note("with p_i = p_f = p_o = 0 this is torch.nn.LSTMCell's step (gate order i, f, j, o "
                        "there, 0.8 folded into its bias): the fused LSTM the book runs")
        return result
    mistakes = [
        ("you return (c, h); return (h, c)", ref[::-1]),
        ("the forget bias 0.8 is missing: σ(f + 0.8 + ...)", variant(forget_bias=0.0)),
        ("the forget bias is 0.8 (the authors' code), not 1.0", variant(forget_bias=1.0)),
        ("you left out the peepholes p_i, p_f, p_o" if peepholes else
         "you still use the peepholes: drop p_i, p_f and p_o", variant(peepholes=not peepholes)),
        ("the candidate needs a tanh: σ(i ...) ⊙ tanh(j)", variant(tanh_j=False)),
        ("h_t = σ(...) ⊙ tanh(c_t): the tanh of the cell state is missing", variant(tanh_c=False)),
        ("the output gate peeps at the NEW cell state: σ(o + p_o ⊙ c_t)", variant(o_new_c=False)),
    ]
    for order in ("".join(p) for p in itertools.permutations("ijfo")):
        pytorch = " (PyTorch's order)" if order == "ifjo" else ""
        mistakes.append((f"you split the gates in the order {', '.join(order)}{pytorch}; the package "
                         "(TensorFlow's form) splits them i, j, f, o", variant(order=order)))
    equation = LSTM_EQUATION if peepholes else re.sub(r" \+ p_[ifo] ⊙ c_(\{t-1\}|t)", "", LSTM_EQUATION)
    _diagnose(result, out, mistakes, equation)
    return result


def check_peephole_step(student_step: Callable, seed: int = 0) -> CheckResult:
    """(a) ``student_step(x, (h, c), cell) -> (h, c)``: one peephole LSTM step against the package's.

    ``cell`` is a :class:`~pgae_lite.model.layers.PeepholeLSTMCell`: use ``cell.weight_x``, ``weight_h``, ``bias``,
    ``peep_i``, ``peep_f``, ``peep_o`` and the forget bias 0.8 (TensorFlow's form, as in the authors' code).
    """
    return _check_step(student_step, True, "peephole LSTM step", seed)


def check_lstm_step(student_step: Callable, seed: int = 0) -> CheckResult:
    """(d) The same step WITHOUT peepholes: the reference is the cell with p_i = p_f = p_o = 0."""
    return _check_step(student_step, False, "LSTM step without peepholes", seed)


# ------------------------------------------------------------------ (b) the GMU
@torch.random.fork_rng(devices=[])
def check_gmu(student: type | nn.Module | Callable, seed: int = 0) -> CheckResult:
    """(b) A GMU forward against :class:`~pgae_lite.model.layers.GatedMultimodalUnit` (paper Sec. 3, "Bottleneck").

    ``student`` is a module class, built as ``cls(action_dim, language_dim, hidden_dim)`` with layers
    named as in the package (``action_linear``, ``language_linear``, ``gate_linear``: the check copies
    the reference weights into them; an instance is rebuilt from its class), or a function
    ``f(gmu, f_action, f_language) -> (h, z)`` that uses the layers of the reference ``gmu``.
    """
    result, gen = CheckResult("GMU forward"), torch.Generator().manual_seed(whole_number("seed", seed, 0, MAX_SEED))
    A, L, H, B = 7, 5, 4, 6
    ref = GatedMultimodalUnit(A, L, H)
    with torch.no_grad():
        for p in ref.parameters():
            p.copy_(torch.rand(p.shape, generator=gen) - 0.5)
    given = copy.deepcopy(ref)                      # the student's function sees a copy
    forward = lambda fa, fl: student(given, fa, fl)  # noqa: E731 - the function form
    if isinstance(student, nn.Module):
        student = type(student)
    if isinstance(student, type):
        forward = given = _build(result, student, A, L, H, name=student.__name__)
        if forward is None:
            return result
        expected = {k: tuple(v.shape) for k, v in ref.state_dict().items()}
        got = {k: tuple(v.shape) for k, v in forward.state_dict().items()}
        if got != expected:
            return result.fail(f"cannot copy the reference weights: your module's parameters are {got}",
                               f"use three nn.Linear layers as GatedMultimodalUnit does: {expected}")
        forward.load_state_dict(ref.state_dict())
    f_act, f_lang = torch.randn(B, A, generator=gen) * 1.5, torch.randn(B, L, generator=gen) * 1.5
    result.note(f"inputs: f_action {tuple(f_act.shape)}, f_language {tuple(f_lang.shape)}, hidden {H}")
    with torch.no_grad():                       # the reference first, on the originals
        a_raw, l_raw = ref.action_linear(f_act), ref.language_linear(f_lang)
        a_h, l_h = torch.tanh(a_raw), torch.tanh(l_raw)
        pre = ref.gate_linear(torch.cat([f_act, f_lang], 1))
        z, z_swapped = torch.sigmoid(pre), torch.sigmoid(ref.gate_linear(torch.cat([f_lang, f_act], 1)))
    inputs = {"f_action": f_act.clone(), "f_language": f_lang.clone()}
    out = _call(result, "your GMU", forward, *inputs.values())
    if not _pair(result, out, "h, z", "your GMU", (B, H)):
        return result
    _unchanged(result, "your GMU", {**inputs, **given.state_dict()},
               {"f_action": f_act, "f_language": f_lang, **ref.state_dict()})
    h = z * a_h + (1 - z) * l_h
    if not all([_compare(result, "h", out[0], h), _compare(result, "z", out[1], z)]):
        _diagnose(result, out, [
            ("you return (z, h); return (h, z)", (z, h)),
            ("the gate z should weight the ACTION features: h = z*A_h + (1-z)*L_h", (z * l_h + (1 - z) * a_h, z)),
            ("the gate reads [f_act; f_lang], the action features first",
             (z_swapped * a_h + (1 - z_swapped) * l_h, z_swapped)),
            ("A_h and L_h need a tanh: A_h = tanh(W_A f_act + b)", (z * a_raw + (1 - z) * l_raw, z)),
            ("z needs a sigmoid, so that it lies between 0 and 1", (pre * a_h + (1 - pre) * l_h, pre)),
            ("the language term is weighted by (1 - z): h = z*A_h + (1-z)*L_h", (z * a_h + l_h, z)),
        ], GMU_EQUATION)
    return result


# ------------------------------------------------------------------ (c) a replacement bottleneck
@torch.random.fork_rng(devices=[])
def check_bottleneck(factory: Callable[[int, int, int], nn.Module], cell: str = "lstm", seed: int = 0) -> CheckResult:
    """(c) A bottleneck that replaces the GMU, e.g. concatenation: h = tanh(W [f_act; f_lang] + b).

    ``factory(action_dim, language_dim, hidden_dim)`` (a class or a function) returns an ``nn.Module``
    whose ``forward(f_action, f_language)`` returns ``(h, z)``, each (batch, hidden). The check runs it
    alone with unequal action and language sizes (as in PGAE-BERT), then as ``model.gmu`` of a tiny
    PGAE (``cell`` "lstm" or "peephole"): a forward and a backward pass on a toy batch.
    """
    seed = whole_number("seed", seed, 0, MAX_SEED)
    result, gen = CheckResult("bottleneck in PGAE"), torch.Generator().manual_seed(seed)
    torch.manual_seed(seed)                                  # the student's initialisation: the same every run
    A, L, H, B = 12, 9, 6, 4
    module = _build(result, factory, A, L, H)
    if module is None:
        return result
    f_act = torch.randn(B, A, generator=gen)
    out = _call(result, f"your module on f_action {(B, A)}, f_language {(B, L)}", module,
                f_act, torch.randn(B, L, generator=gen))
    if out is RAISED:
        return result.note("forward(f_action, f_language) takes both; the language features have language_dim "
                           "numbers (in PGAE-BERT 384, not 400)")
    if not _pair(result, out, "h, z", "your module", (B, H)):
        gate = "without a gate, return a constant one, e.g. torch.full_like(h, 0.5)"
        return result if out is None else result.note(gate)
    for name, t in zip("hz", out):
        if not isinstance(t, torch.Tensor) or t.shape != (B, H):
            result.fail(f"{name} has {_shape(t)}; expected (batch, hidden) = {(B, H)}")
    if not result:
        return result
    for name, t in zip("hz", out):  # NaN or inf fails; the PGAE below shows its effect
        problem = _value_problem(t, f_act)
        if problem:
            result.fail(f"{name} {problem}")
    if result:
        result.ok(f"alone: finite h and z of shape (batch, hidden) = {(B, H)}")
    model = PGAE(ModelConfig(units=8, layers=2, hidden=H, cell=cell, joint_feedback="predicted"))
    sizes = (model.cfg.state_dim, model.language_encoder.output_dim, H)
    gmu = _build(result, factory, *sizes)
    if gmu is None:
        return result
    model.gmu = gmu                                          # in place of the GMU; PGAE.encode calls self.gmu
    toy = toy_dataset(1, seed, patterns=[0, 7, 80, 101, 140])  # five recordings, 100 or 50 steps
    batch = make_batch(Normaliser.fit(toy).tensors(toy), torch.arange(5), signal=torch.arange(5),  # one each
                       alternative=torch.arange(5) % DESCRIPTIONS)
    out = _call(result, "PGAE with it", lambda: model(batch, teacher_language=True))
    if out is RAISED:
        return result
    loss = pgae_loss(out, batch, word_weights())[0]
    if not torch.isfinite(loss):
        return result.fail(f"the loss is {loss.item()}", "does h contain NaN or inf?")
    _call(result, "the backward pass", loss.backward)
    if not result:
        return result
    result.ok(f"as model.gmu = factory{sizes} of a tiny PGAE: logits {tuple(out['logits'].shape)}, "
              f"joints {tuple(out['joints'].shape)}, loss {loss.item():.3f}, backward pass done")
    dead = [n for n, p in model.gmu.named_parameters() if p.grad is None or not torch.isfinite(p.grad).all()]
    if dead:
        result.fail(f"no gradient reaches your parameter(s) {dead}", "is every layer used to compute h?")
    for part in ("action_encoder", "language_encoder"):
        if all(p.grad is None or not p.grad.any() for p in getattr(model, part).parameters()):
            result.fail(f"no gradient reaches the {part}", "h must depend on both features (no .detach())")
    if result:
        result.ok("the gradient reaches every parameter of your module and both encoders")
    book = _build(result, factory, 400, 400, 50)
    if book is not None:
        result.note(f"parameters at the book's sizes (400, 400, 50): yours {count_parameters(book):,}, "
                    f"the GMU's {count_parameters(GatedMultimodalUnit(400, 400, 50)):,}")
    return result


# ------------------------------------------------------------------ (e) signal probabilities
def check_signal_probs(probs: Sequence[float] | dict[str, float], drop: str | None = "repeat both") -> CheckResult:
    """(e) Training probabilities of the signals with ``drop`` left out: a list in the order of
    :data:`~pgae_lite.world.words.SIGNALS`, or a dict by signal name (missing names count as 0).
    Train with them as ``get_profile(..., signal_probs=probs)`` (:class:`~pgae_lite.train.config.TrainConfig`)."""
    result = CheckResult(f"signal probabilities without {drop!r}" if drop else "signal probabilities")
    if drop is not None and drop not in SIGNALS:
        return result.fail(f"drop is {drop!r}; expected None or one of the signals: "
                           f"{', '.join(SIGNALS)}")
    if isinstance(probs, dict):
        unknown = sorted(set(probs) - set(SIGNALS), key=repr)
        if unknown:
            return result.fail(f"unknown signal name(s) {unknown}; "
                               f"the signals are: {', '.join(SIGNALS)}")
        probs = [probs.get(s, 0.0) for s in SIGNALS]
    p = _numbers(result, probs, "the probabilities")
    if p is None:
        return result.note(f"give {len(SIGNALS)} numbers in the order {list(SIGNALS)}, "
                           "or a dict by signal name")
    if len(p) != len(SIGNALS):
        return result.fail(f"{len(p)} probabilities; expected {len(SIGNALS)}, one per signal: {list(SIGNALS)}")
    if min(p) < 0:
        result.fail(f"a negative probability, {min(p)}")
    if not math.isclose(sum(p), 1.0, abs_tol=1e-6):
        result.fail(f"they sum to {sum(p):.4f}, not 1", "divide each by their sum")
    dropped = SIGNALS.index(drop) if drop else None
    for k, (s, v) in enumerate(zip(SIGNALS, p)):
        if k == dropped and v != 0:
            result.fail(f"{s!r} still has probability {v:.4f}; it should be 0")
        elif k != dropped and v <= 0:
            result.fail(f"{s!r} has probability 0", "a signal never trained cannot be tested in Table 1")
    if not result:
        return result
    result.ok(f"{len(p)} probabilities summing to 1" + (f", 0 for {drop!r}" if drop else "")
              + "; train with them: get_profile(..., signal_probs=probs)")
    kept = [q if k != dropped else 0.0 for k, q in enumerate(SIGNAL_PROBS)]
    authors = [q / sum(kept) for q in kept]
    if all(math.isclose(a, b, abs_tol=1e-4) for a, b in zip(p, authors)):
        result.ok("the other signals keep the authors' ratios")
    else:
        result.note(f"the authors' ratios, renormalised, would be {[round(a, 4) for a in authors]}")
    drawn = sample_signals(9000, torch.Generator().manual_seed(0), probs=tuple(p)).bincount(minlength=5) / 9000
    shares = ", ".join(f"{s} {f:.3f}" for s, f in zip(SIGNALS, drawn))
    result.note(f"share of 9000 draws, as training draws them: {shares}")
    return result


__all__ = ["check_peephole_step", "check_lstm_step", "check_gmu", "check_bottleneck", "check_signal_probs"]
