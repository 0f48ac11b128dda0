"""Building blocks of PGAE: the peephole LSTM and the Gated Multimodal Unit.

Paper, Sec. 3: "The LSTMs we use here [...] are a peephole LSTM" (Gers &
Schmidhuber 2000, in TensorFlow's form as in the authors' code) and the
bottleneck "is based on the GMU" (Arevalo et al. 2017).

Both recurrent classes share one interface, that of ``torch.nn.LSTM`` with
``batch_first=True``: ``forward(x, lengths, state) -> (outputs, (h, c))`` with
``h, c`` of shape (layers, batch, units), and ``step(x_t, state)`` for one time
step. A sample's final state is the state after its last valid step. Inside
:func:`recurrent_layers` a layer of one's own with this interface stands in
for them in every encoder and decoder (not in the paper: the course's GRU lab).
"""
from __future__ import annotations

import contextlib
from typing import Callable, Iterator

import torch
from torch import nn

State = tuple[torch.Tensor, torch.Tensor]  # (h, c), each (layers, batch, units)


class PeepholeLSTMCell(nn.Module):
    """One peephole LSTM layer, one time step (TensorFlow's gate order i, j, f, o)."""

    def __init__(self, input_size: int, hidden_size: int, forget_bias: float = 0.8):
        super().__init__()
        self.hidden_size = hidden_size
        self.forget_bias = forget_bias
        self.weight_x = nn.Parameter(torch.empty(input_size, 4 * hidden_size))
        self.weight_h = nn.Parameter(torch.empty(hidden_size, 4 * hidden_size))
        self.bias = nn.Parameter(torch.empty(4 * hidden_size))
        self.peep_i = nn.Parameter(torch.empty(hidden_size))
        self.peep_f = nn.Parameter(torch.empty(hidden_size))
        self.peep_o = nn.Parameter(torch.empty(hidden_size))
        for p in self.parameters():
            nn.init.uniform_(p, -0.1, 0.1)  # authors' code: every parameter U(-0.1, 0.1)

    def forward(self, gates_x: torch.Tensor, h: torch.Tensor, c: torch.Tensor) -> State:
        """``gates_x`` = x_t W_x + b (batch, 4H), precomputed for all steps at once."""
        gates = gates_x + h @ self.weight_h                      # (batch, 4H)
        i, j, f, o = gates.chunk(4, dim=1)                       # each (batch, H)
        # c_t = σ(f + b_f + p_f ⊙ c_{t-1}) ⊙ c_{t-1} + σ(i + p_i ⊙ c_{t-1}) ⊙ tanh(j)
        c_new = (torch.sigmoid(f + self.forget_bias + self.peep_f * c) * c
                 + torch.sigmoid(i + self.peep_i * c) * torch.tanh(j))
        # h_t = σ(o + p_o ⊙ c_t) ⊙ tanh(c_t)
        h_new = torch.sigmoid(o + self.peep_o * c_new) * torch.tanh(c_new)
        return h_new, c_new


class PeepholeLSTM(nn.Module):
    """A stack of peephole LSTM layers over a batch-first sequence (the paper's cell)."""

    def __init__(self, input_size: int, hidden_size: int, num_layers: int = 2, forget_bias: float = 0.8):
        super().__init__()
        self.hidden_size, self.num_layers = hidden_size, num_layers
        self.cells = nn.ModuleList(
            PeepholeLSTMCell(input_size if layer == 0 else hidden_size, hidden_size, forget_bias)
            for layer in range(num_layers))

    @property
    def input_weight(self) -> nn.Parameter:
        """First layer's input weights (input, 4H): for one-hot inputs, a word embedding."""
        return self.cells[0].weight_x

    def zero_state(self, batch: int, like: torch.Tensor) -> State:
        z = like.new_zeros(self.num_layers, batch, self.hidden_size)
        return z, z.clone()

    def forward(self, x: torch.Tensor, lengths: torch.Tensor | None = None,
                state: State | None = None) -> tuple[torch.Tensor, State]:
        """x (batch, T, input) -> outputs (batch, T, H) and the final (h, c).

        Past a sample's length the state is frozen (not detached), so its
        final state is the one after its last valid step.
        """
        batch, steps, _ = x.shape
        h0, c0 = state if state is not None else self.zero_state(batch, x)
        valid = None
        if lengths is not None:  # (T, batch, 1) True where step t is inside the sequence
            valid = (torch.arange(steps, device=x.device)[:, None] < lengths.to(x.device)[None, :])[..., None]
        layer_in, hs, cs = x, [], []
        for layer, cell in enumerate(self.cells):
            gates_x = (layer_in @ cell.weight_x + cell.bias).unbind(1)  # T x (batch, 4H)
            h, c = h0[layer], c0[layer]
            outs = []
            for t in range(steps):
                h_new, c_new = cell(gates_x[t], h, c)
                if valid is not None:
                    h_new = torch.where(valid[t], h_new, h)
                    c_new = torch.where(valid[t], c_new, c)
                h, c = h_new, c_new
                outs.append(h)
            layer_in = torch.stack(outs, 1)                      # (batch, T, H)
            hs.append(h)
            cs.append(c)
        return layer_in, (torch.stack(hs), torch.stack(cs))

    def step(self, x_t: torch.Tensor, state: State) -> tuple[torch.Tensor, State]:
        """One time step for all layers: x_t (batch, input) -> output (batch, H), new state."""
        h0, c0 = state
        hs, cs, inp = [], [], x_t
        for layer, cell in enumerate(self.cells):
            h, c = cell(inp @ cell.weight_x + cell.bias, h0[layer], c0[layer])
            hs.append(h)
            cs.append(c)
            inp = h
        return inp, (torch.stack(hs), torch.stack(cs))


class FusedLSTM(nn.Module):
    """``torch.nn.LSTM`` (no peepholes) behind the same interface as :class:`PeepholeLSTM`.

    Deviation from paper: no peephole connections; in exchange PyTorch's fused
    kernel runs ~3x faster on a CPU. Choose the paper's cell with ``cell="peephole"``.
    """

    def __init__(self, input_size: int, hidden_size: int, num_layers: int = 2, forget_bias: float = 0.8):
        super().__init__()
        self.hidden_size, self.num_layers = hidden_size, num_layers
        self.lstm = nn.LSTM(input_size, hidden_size, num_layers, batch_first=True)
        for p in self.lstm.parameters():
            nn.init.uniform_(p, -0.1, 0.1)
        with torch.no_grad():  # PyTorch's gate order is i, f, g, o: add the forget bias once
            for layer in range(num_layers):
                getattr(self.lstm, f"bias_ih_l{layer}")[hidden_size:2 * hidden_size] += forget_bias

    @property
    def input_weight(self) -> nn.Parameter:
        """First layer's input weights (4H, input): for one-hot inputs, a word embedding."""
        return self.lstm.weight_ih_l0

    def forward(self, x: torch.Tensor, lengths: torch.Tensor | None = None,
                state: State | None = None) -> tuple[torch.Tensor, State]:
        if lengths is None:
            return self.lstm(x, state)
        # Samples of equal length run together, each group for exactly its length.
        # (pack_padded_sequence gives the same result but is ~3x slower on a CPU.)
        batch, steps, _ = x.shape
        lengths = lengths.to(x.device)
        out = x.new_zeros(batch, steps, self.hidden_size)
        h = x.new_zeros(self.num_layers, batch, self.hidden_size)
        c = torch.zeros_like(h)
        for n in lengths.unique().tolist():
            idx = (lengths == n).nonzero().squeeze(1)
            s = None if state is None else (state[0][:, idx], state[1][:, idx])
            y, (h_n, c_n) = self.lstm(x[idx, :n], s)            # y (group, n, H)
            out = out.index_copy(0, idx, nn.functional.pad(y, (0, 0, 0, steps - n)))
            h, c = h.index_copy(1, idx, h_n), c.index_copy(1, idx, c_n)
        return out, (h, c)

    def step(self, x_t: torch.Tensor, state: State) -> tuple[torch.Tensor, State]:
        # One cell call per layer with nn.LSTM's own weights: cheaper than a length-1 nn.LSTM call.
        h0, c0 = state
        hs, cs, inp = [], [], x_t
        for layer in range(self.num_layers):
            weights = [getattr(self.lstm, f"{n}_l{layer}") for n in ("weight_ih", "weight_hh", "bias_ih", "bias_hh")]
            h, c = torch.lstm_cell(inp, (h0[layer], c0[layer]), *weights)
            hs.append(h)
            cs.append(c)
            inp = h
        return inp, (torch.stack(hs), torch.stack(cs))


#: the factories of the :func:`recurrent_layers` blocks that are open, the innermost last
_LAYER_FACTORIES: list[Callable[[int, int, int], nn.Module]] = []


@contextlib.contextmanager
def recurrent_layers(factory: Callable[[int, int, int], nn.Module]) -> Iterator[None]:
    """Inside the block, every recurrent layer a model builds is ``factory(input_size, hidden_size, num_layers)``
    in place of its config's cell: a layer of one's own (the course's GRU lab; not in the paper) in every encoder
    and decoder. The layer needs :class:`PeepholeLSTM`'s interface: ``forward``, ``step`` and ``input_weight``.

        with recurrent_layers(MyGRU):
            model = PGAE(cfg)
    """
    if not callable(factory):
        raise TypeError(f"recurrent_layers takes a class or function factory(input_size, hidden_size, num_layers); "
                        f"got {type(factory).__name__}")
    _LAYER_FACTORIES.append(factory)
    try:
        yield
    finally:
        _LAYER_FACTORIES.pop()


def make_recurrent(cell: str, input_size: int, hidden_size: int, num_layers: int) -> nn.Module:
    """``cell="peephole"`` (the paper's) or ``"lstm"`` (fused, faster); inside :func:`recurrent_layers`, its
    factory's layer."""
    if _LAYER_FACTORIES:
        layer = _LAYER_FACTORIES[-1](input_size, hidden_size, num_layers)
        if not isinstance(layer, nn.Module):
            raise TypeError(f"the recurrent_layers factory returned {type(layer).__name__}; expected an nn.Module "
                            "with PeepholeLSTM's interface")
        return layer
    if cell == "peephole":
        return PeepholeLSTM(input_size, hidden_size, num_layers)
    if cell == "lstm":
        return FusedLSTM(input_size, hidden_size, num_layers)
    raise ValueError(f"unknown cell {cell!r}; the cells are: peephole, lstm")


def state_to_vector(state: State) -> torch.Tensor:
    """Final (h, c) of every layer -> [c_0; h_0; c_1; h_1] (batch, 2 x layers x H), the authors' order."""
    h, c = state
    return torch.cat([t for layer in range(h.shape[0]) for t in (c[layer], h[layer])], dim=1)


def vector_to_state(v: torch.Tensor, num_layers: int) -> State:
    """Inverse of :func:`state_to_vector`: (batch, 2 x layers x H) -> (h, c)."""
    parts = v.chunk(2 * num_layers, dim=1)                       # c_0, h_0, c_1, h_1, ...
    c = torch.stack(parts[0::2]).contiguous()
    h = torch.stack(parts[1::2]).contiguous()
    return h, c


class GatedMultimodalUnit(nn.Module):
    """The GMU bottleneck (Arevalo et al. 2017), paper Sec. 3, "Bottleneck".

    Mixes the action and language features per dimension with a learnt gate z.
    ``normalise_action``: the book recipe's layer normalisation of W_A f_act + b (below).
    """

    def __init__(self, action_dim: int, language_dim: int, hidden_dim: int = 50,
                 normalise_action: bool = False):
        super().__init__()
        self.action_linear = nn.Linear(action_dim, hidden_dim)
        self.language_linear = nn.Linear(language_dim, hidden_dim)
        self.gate_linear = nn.Linear(action_dim + language_dim, hidden_dim)
        self.normalise_action = normalise_action

    def forward(self, f_action: torch.Tensor, f_language: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """Returns the shared representation h and the gate z, both (batch, hidden)."""
        a = self.action_linear(f_action)                          # W_A f_act + b, (batch, hidden)
        if self.normalise_action:
            # Deviation from paper: a is normalised to mean 0, variance 1 over its dimensions before
            # the tanh. f_act holds the LSTM's unbounded cell states; without this, some seeds push a
            # so far that tanh saturates for every sample and describe never learns (ModelConfig.gmu_norm).
            a = nn.functional.layer_norm(a, a.shape[-1:])
        a_h = torch.tanh(a)                                      # A_h = tanh(W_A f_act + b)
        l_h = torch.tanh(self.language_linear(f_language))       # L_h = tanh(W_L f_lang + b)
        z = torch.sigmoid(self.gate_linear(torch.cat([f_action, f_language], dim=1)))  # z = σ(W_z [f_act; f_lang] + b)
        h = z * a_h + (1 - z) * l_h                              # h = z ⊙ A_h + (1 − z) ⊙ L_h
        return h, z


class ConcatBottleneck(nn.Module):
    """The GMU's ablation (not in the paper): h = tanh(W [f_act; f_lang] + b), no gate.

    The reference answer of the book's concatenation exercises (chapters 04, 05, A1) and the
    ``concat`` row of ``benchmarks/ablations.py``. It returns a constant gate of 0.5, so that
    every plot of z still works.
    """

    def __init__(self, action_dim: int, language_dim: int, hidden_dim: int = 50):
        super().__init__()
        self.linear = nn.Linear(action_dim + language_dim, hidden_dim)

    def forward(self, f_action: torch.Tensor, f_language: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        h = torch.tanh(self.linear(torch.cat([f_action, f_language], dim=1)))    # (B, hidden)
        return h, torch.full_like(h, 0.5)

