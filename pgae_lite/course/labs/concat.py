"""Lab: the GMU replaced by concatenation, h = tanh(W [f_act; f_lang] + b) (paper Sec. 3, "Bottleneck").

The paper joins its two encoders in a Gated Multimodal Unit (Arevalo et al. 2017)::

    A_h = tanh(W_A f_act + b),  L_h = tanh(W_L f_lang + b),  z = σ(W_z [f_act; f_lang] + b)
    h   = z ⊙ A_h + (1 − z) ⊙ L_h

The lab's change is the simplest fusion, one linear map over both features and no gate. At the
recipe's 300 epochs the two end level (``results/ablations.json``); early in a training the
concatenation lags on the tasks that write words, most of all on the seeds where its h stalls. The
lab trains for 20 epochs (:data:`EPOCHS`), a class period on a laptop's CPU (``results/lab-concat.json``).

A student's bottleneck is a factory ``factory(action_dim, language_dim, hidden_dim) -> nn.Module``
whose ``forward(f_action, f_language)`` returns ``(h, z)``, as ``model.gmu`` of PGAE. :func:`check`
judges it by its behaviour (:func:`pgae_lite.exercises.model.check_bottleneck`: alone, then inside a small
PGAE, forward and backward) and by its structure (one linear map over [f_act; f_lang], no gate, h
reading both features, the tanh). :func:`run` trains PGAE with it; :func:`train_at_budget` is the
training the GRU lab shares.
"""
from __future__ import annotations

from typing import Callable

import torch
from torch import nn

from pgae_lite.config import Profile, get_profile
from pgae_lite.evaluate.table1 import evaluate
from pgae_lite.exercises import check_bottleneck
from pgae_lite.exercises.result import RAISED, CheckResult, _build, _call, _compare, _diagnose
from pgae_lite.model.layers import ConcatBottleneck, GatedMultimodalUnit
from pgae_lite.model.pgae import PGAE, count_parameters
from pgae_lite.model.signals import make_batch
from pgae_lite.runs.data import worker_dataset
from pgae_lite.train.loop import Trained, train
from pgae_lite.util.checks import MAX_SEED, shown, whole_number
from pgae_lite.util.errors import ArgumentTypeError
from pgae_lite.world.words import SIGNALS

TITLE = "The GMU replaced by concatenation"
STUDENT_NAME = "MyConcat"           # the student's component, in the lab's notebook

#: the lab's budget, where every seed of the GMU is ahead of every seed of the concatenation on describe and
#: repeat language (results/lab-concat.json). Shorter than chapter 04's 30 epochs: the shorter the training,
#: the more a seed whose h stalls lags (the recipe's 300 end level). The smoke profile keeps its 3.
EPOCHS = 20

EQUATION = "h = tanh(W [f_act; f_lang] + b), one linear map over both features, no gate (z a constant)"

FIGURES = {"describe": "describe: accuracy %", "repeat_language": "repeat language: accuracy %",
           "execute_nrmse": "execute: joints nRMSE %", "describe_saturated": "describe: h saturated, % of entries"}


def book_gmu(action_dim: int, language_dim: int, hidden_dim: int = 50) -> nn.Module:
    """The book's bottleneck: the GMU, its W_A f_act + b layer-normalised (``ModelConfig.gmu_norm``)."""
    return GatedMultimodalUnit(action_dim, language_dim, hidden_dim, normalise_action=True)


BASELINE = book_gmu
REFERENCE = ConcatBottleneck        # the package's: h = tanh(W [f_act; f_lang] + b), z = 0.5


# ------------------------------------------------------------------ the run
def train_at_budget(build: Callable[[Profile], nn.Module], seed: int = 0, profile: Profile | str | None = None,
                    epochs: int = EPOCHS, progress: bool = False, name: str = TITLE) -> tuple[Trained, dict]:
    """PGAE as ``build(profile)`` makes it (under ``torch.manual_seed(seed)``), trained for ``epochs`` (the
    profile's own when fewer) on the profile's simulated data; the trained model and its Table 1 cells.
    ``name``: the progress bar's."""
    seed = whole_number("seed", seed, 0, MAX_SEED)
    profile = get_profile(profile)                      # None: $PGAE_LITE_PROFILE, else book
    profile = get_profile(profile, seed=seed, epochs=min(whole_number("epochs", epochs, 1), profile.train.epochs))
    data = worker_dataset(None, profile, "cpu")         # the chapters' data, from the cache (made if missing)
    torch.manual_seed(seed)                             # the same initial weights for the same seed
    trained = train(data, profile, model=build(profile), progress=progress, name=name)
    cells, _ = evaluate(trained.model, data, trained.normaliser)
    return trained, cells


def run(component: Callable[[int, int, int], nn.Module], seed: int = 0, profile: Profile | str | None = None,
        progress: bool = False) -> dict[str, float]:
    """PGAE with ``component(action_dim, language_dim, hidden_dim)`` as its bottleneck, trained for
    :data:`EPOCHS` epochs: the describe and repeat-language accuracies, execute's nRMSE and the share of h
    saturated under describe (%)."""
    if not callable(component):
        raise ArgumentTypeError(f"component must be a class or function that builds the bottleneck, "
                                f"component(action_dim, language_dim, hidden_dim); got {shown(component)}")

    def build(profile: Profile) -> nn.Module:
        model = PGAE(profile.model, profile.data.the_world.lexicon)
        gmu = component(model.cfg.state_dim, model.language_encoder.output_dim, model.cfg.hidden)
        if not isinstance(gmu, nn.Module):
            raise ArgumentTypeError(f"component(...) returned {shown(gmu)}, not an nn.Module; "
                                    "check it first: check(component)")
        model.gmu = gmu                                 # in place of the GMU; PGAE.encode calls self.gmu
        return model

    trained, cells = train_at_budget(build, seed, profile, progress=progress)
    return {"describe": cells["describe"]["accuracy"], "repeat_language": cells["repeat language"]["accuracy"],
            "execute_nrmse": cells["execute"]["nrmse"],
            "describe_saturated": saturated(trained.model, worker_dataset(None, trained.profile, "cpu"),
                                            trained.normaliser)}


def saturated(model: nn.Module, data, normaliser, signal: str = "describe") -> float:
    """% of the entries of h with |h| > 0.99 on the test split's samples under ``signal``: a tanh stuck at ±1,
    where h is the same for every action and no gradient passes (the describe collapse, experiments/HISTORY.md)."""
    test = data.split("test")
    n, tensors = len(test), normaliser.tensors(test, next(model.parameters()).device)
    batch = make_batch(tensors, torch.arange(n), signal=torch.full((n,), SIGNALS.index(signal)),
                       alternative=torch.zeros(n, dtype=torch.long))
    with torch.no_grad():
        h, _ = model.eval().encode(batch)                                   # (n, hidden)
    return 100 * float((h.abs() > 0.99).float().mean())


# ------------------------------------------------------------------ the check
def _linear_count(inputs: int, outputs: int) -> int:
    return inputs * outputs + outputs                   # W (outputs, inputs) and b


@torch.random.fork_rng(devices=[])                     # the student's global random state stays as it was
def check(component: Callable[[int, int, int], nn.Module], seed: int = 0) -> CheckResult:
    """Is ``component`` a concatenation bottleneck? Its structure (one linear map over [f_act; f_lang], no gate,
    h reading both features through a tanh) and its behaviour as PGAE's bottleneck (``check_bottleneck``)."""
    seed = whole_number("seed", seed, 0, MAX_SEED)
    result, gen = CheckResult("concatenation in place of the GMU"), torch.Generator().manual_seed(seed)
    A, L, H, B = 12, 9, 6, 5                            # unequal sizes, as in PGAE-BERT
    torch.manual_seed(seed)
    module = _build(result, component, A, L, H)
    if module is not None:
        result.note(f"structure, at action_dim {A}, language_dim {L}, hidden_dim {H}:")
        _structure(result, module, A, L, H)
        result.note(f"behaviour, on {B} random samples:")
        _behaviour(result, module, torch.randn(B, A, generator=gen) * 1.5, torch.randn(B, L, generator=gen) * 1.5,
                   torch.randn(B, A, generator=gen) * 1.5, torch.randn(B, L, generator=gen) * 1.5)
    behaviour = check_bottleneck(component, seed=seed)  # alone, then as model.gmu of a small PGAE
    result.note("as PGAE's bottleneck:")
    result.lines += behaviour.lines
    result.passed = result.passed and behaviour.passed
    return result


def _structure(result: CheckResult, module: nn.Module, A: int, L: int, H: int) -> None:
    """The parameters: one linear map over [f_act; f_lang] and nothing that gates."""
    names = _call(result, "listing your module's parameters", lambda: [n for n, _ in module.named_parameters()])
    if names is RAISED:
        result.note("does your __init__ call super().__init__() first?")
        return
    gates = [n for n in names if "gate" in n.lower()]
    if gates:
        result.fail(f"your module has gate parameters ({', '.join(gates)}): concatenation has no gate",
                    "keep one nn.Linear(action_dim + language_dim, hidden_dim) and return a constant z")
    count, one = count_parameters(module), _linear_count(A + L, H)
    known = {_linear_count(A, H) + _linear_count(L, H) + one:
             "the GMU's (W_A, W_L and the gate W_z): concatenation keeps one linear map and drops the gate",
             _linear_count(A, H) + _linear_count(L, H):
             "two linear maps, one per feature; the equation has one over both, [f_act; f_lang]",
             _linear_count(A, H): "one linear map over f_act alone: h ignores the language features",
             _linear_count(L, H): "one linear map over f_lang alone: h ignores the action features"}
    if count == one:
        result.ok(f"{count} parameters: one linear map over [f_act; f_lang], (A + L)·H + H = {one}")
    else:
        result.fail(f"{count} parameters; one linear map over [f_act; f_lang] has (A + L)·H + H = {one}"
                    + (f": yours is {known[count]}" if count in known else ""), f"compute {EQUATION}")


def _behaviour(result: CheckResult, module: nn.Module, f_act, f_lang, other_act, other_lang) -> None:
    """h against the equation with the module's own linear map; h reads both features; z is no gate."""
    outs = []
    for a, lang in ((f_act, f_lang), (other_act, f_lang), (f_act, other_lang), (other_act, other_lang)):
        with torch.no_grad():
            outs.append(_call(result, "your module", module, a, lang))
        if outs[-1] is RAISED:
            return
    shape = _pair_shape(outs[0])
    if shape is None or shape[0] != len(f_act) or any(_pair_shape(o) != shape for o in outs):
        result.fail("forward(f_action, f_language) must return (h, z), two tensors of shape (batch, hidden_dim)",
                    "without a gate, return a constant z: torch.full_like(h, 0.5)")
        return
    (h, z), (h_act, _), (h_lang, _), (_, z_other) = outs
    for who, changed in (("f_action", h_act), ("f_language", h_lang)):
        if torch.allclose(h, changed):
            result.fail(f"h does not change when {who} changes: your module ignores it",
                        "concatenate both features, torch.cat([f_action, f_language], dim=1)")
    if not torch.allclose(z, z_other) or not torch.allclose(z, z.flatten()[0].expand_as(z)):
        result.fail("z changes with the inputs: your module still computes a gate",
                    "concatenation has no gate; return a constant z, e.g. torch.full_like(h, 0.5)")
    linears = [m for m in module.modules() if isinstance(m, nn.Linear)]
    if len(linears) != 1 or linears[0].in_features != f_act.shape[1] + f_lang.shape[1]:
        result.note("the check compares h with the equation when your module holds one "
                    "nn.Linear(action_dim + language_dim, hidden_dim)")
        return
    linear = linears[0]
    with torch.no_grad():
        pre = linear(torch.cat([f_act, f_lang], dim=1))                  # W [f_act; f_lang] + b, (B, H)
        swapped = linear(torch.cat([f_lang, f_act], dim=1))
    if not _compare(result, "h", h, torch.tanh(pre)):                    # h = tanh(W [f_act; f_lang] + b)
        _diagnose(result, (h,), [
            ("h needs a tanh: h = tanh(W [f_act; f_lang] + b)", (pre,)),
            ("h = tanh(...), not a sigmoid", (torch.sigmoid(pre),)),
            ("h = tanh(...), not a ReLU", (torch.relu(pre),)),
            ("concatenate the action features first: [f_act; f_lang]", (torch.tanh(swapped),)),
        ], EQUATION)


def _pair_shape(out) -> tuple | None:
    """The shape of h when ``out`` is a pair (h, z) of tensors of one shape; else None."""
    if not isinstance(out, (tuple, list)) or len(out) != 2 or not all(isinstance(t, torch.Tensor) for t in out):
        return None
    return tuple(out[0].shape) if out[0].shape == out[1].shape and out[0].dim() == 2 else None


# ------------------------------------------------------------------ deliberate mistakes (CI runs them)
class NoTanh(ConcatBottleneck):
    """h = W [f_act; f_lang] + b: the tanh left out."""

    def forward(self, f_action, f_language):
        h = self.linear(torch.cat([f_action, f_language], dim=1))
        return h, torch.full_like(h, 0.5)


class ActionOnly(nn.Module):
    """h = tanh(W_A f_act + b): the language features left out."""

    def __init__(self, action_dim: int, language_dim: int, hidden_dim: int = 50):
        super().__init__()
        self.linear = nn.Linear(action_dim, hidden_dim)

    def forward(self, f_action, f_language):
        h = torch.tanh(self.linear(f_action))
        return h, torch.full_like(h, 0.5)


class GateKept(ConcatBottleneck):
    """The concatenation, and a learnt gate z = σ(W_z [f_act; f_lang] + b) returned beside it."""

    def __init__(self, action_dim: int, language_dim: int, hidden_dim: int = 50):
        super().__init__(action_dim, language_dim, hidden_dim)
        self.gate_linear = nn.Linear(action_dim + language_dim, hidden_dim)

    def forward(self, f_action, f_language):
        both = torch.cat([f_action, f_language], dim=1)
        return torch.tanh(self.linear(both)), torch.sigmoid(self.gate_linear(both))


WRONG = {
    "the tanh left out": (NoTanh, ["h needs a tanh"]),
    "the language features left out": (ActionOnly, ["h does not change when f_language changes",
                                                    "no gradient reaches the language_encoder"]),
    "a gate kept": (GateKept, ["gate parameters", "z changes with the inputs"]),
}

__all__ = ["BASELINE", "EPOCHS", "FIGURES", "REFERENCE", "STUDENT_NAME", "TITLE", "WRONG", "book_gmu", "check", "run",
           "train_at_budget"]
