"""PGAE: paired gated autoencoders (paper Sec. 3, Fig. 3).

Two autoencoders, language and action, joined in a GMU bottleneck:

    f_lang = LanguageEncoder(signal + words)          (Sec. 3, Language Autoencoder)
    f_act  = ActionEncoder([v_t; j_t] for each step)   (Sec. 3, Action Autoencoder)
    h, z   = GMU(f_act, f_lang)                        (Sec. 3, Bottleneck)
    words  = LanguageDecoder(h)                        autoregressive from <BOS>
    joints = ActionDecoder(h, vision, start joints)    j_{t+1} = tanh(W y_t + b)

Sizes follow the authors' code: LSTMs of 100 units in 2 layers, h of 50,
30 visual features and 5 joints per step.

Deviation from paper: with ``time_stride`` k (3 in the book) one step of the
action LSTMs covers k time steps: the encoder reads every k-th step, x_0, x_k,
...; the decoder reads v_t and writes [ĵ_{t+1}; ...; ĵ_{t+k}], every pose.
1/k of the LSTM steps.

``PGAE(cfg, lexicon=...)`` builds the model for a larger vocabulary (not from
the paper: :func:`pgae_lite.world.colours.with_colour`); the default is the paper's 23 words.
"""
from __future__ import annotations

import torch
from torch import nn

from pgae_lite.data.dataset import JOINT_DIM, VISION_DIM
from pgae_lite.model.config import ModelConfig
from pgae_lite.model.language import LanguageEncoderBase
from pgae_lite.model.layers import GatedMultimodalUnit, make_recurrent, state_to_vector, vector_to_state
from pgae_lite.model.loss import LearnsFromSignals
from pgae_lite.model.plan import PlanHead
from pgae_lite.model.signals import SignalBatch
from pgae_lite.world.words import DEFAULT_LEXICON, VOCABULARY, Lexicon, word_weights

WORDS = len(VOCABULARY)


def lstm_steps_of(steps: torch.Tensor, stride: int) -> torch.Tensor:
    """LSTM steps that cover ``steps`` time steps, ``stride`` per LSTM step: ceil(steps / stride)."""
    return torch.div(steps + stride - 1, stride, rounding_mode="floor")


def embedding_init_(rnn: nn.Module) -> None:
    """Initialise the input weights of an LSTM fed one-hot words like a word embedding, N(0, 1).

    Deviation from paper: the authors' code draws every weight from U(-0.1, 0.1).
    With one-hot inputs that makes all words look alike to the LSTM, and the
    language path sat on a plateau for hundreds of epochs (measured: a
    language autoencoder stayed at chance for 1000 steps; with N(0, 1) it
    reached 100% in 200).
    """
    nn.init.normal_(rnn.input_weight, 0.0, 1.0)


class LanguageEncoder(LanguageEncoderBase):
    """LSTM over one-hot tokens (signal first); f = final [c; h] of every layer.

    The tokens are those of :func:`pgae_lite.model.signals.make_batch`: the signal s first, as
    token 23 + s, then word indices. With a lexicon of V > 23 words the signal's one-hot
    dimension is V + s (the words' come first), so the first token moves by V - 23.
    It reads the dataset's words only (:class:`~pgae_lite.model.language.LanguageEncoderBase`,
    the interface every language encoder has); the pretrained encoders of :mod:`pgae_lite.bert`
    read any text.
    """

    def __init__(self, cfg: ModelConfig, lexicon: Lexicon = DEFAULT_LEXICON):
        super().__init__()
        self.input_dim = lexicon.input_dim                  # 28 for the paper's words
        self.signal_shift = lexicon.size - len(VOCABULARY)    # 0 for the paper's
        self.rnn = make_recurrent(cfg.cell, self.input_dim, cfg.units, cfg.layers)
        embedding_init_(self.rnn)
        self.output_dim = cfg.state_dim

    def forward(self, tokens: torch.Tensor, lengths: torch.Tensor) -> torch.Tensor:
        if self.signal_shift:                                   # signal 23 + s -> V + s
            tokens = torch.cat([tokens[:, :1] + self.signal_shift, tokens[:, 1:]], 1)
        x = nn.functional.one_hot(tokens, self.input_dim).float()   # (B, 5, words + 5 signals)
        _, state = self.rnn(x, lengths)
        return state_to_vector(state)                           # (B, 2 · layers · units)


class ActionEncoder(nn.Module):
    """LSTM over [visual features; joints] per step; f = final [c; h] of every layer.

    With ``time_stride`` k > 1 it reads every k-th step: x_0, x_k, x_2k, ...
    """

    def __init__(self, cfg: ModelConfig):
        super().__init__()
        self.stride = cfg.time_stride
        self.rnn = make_recurrent(cfg.cell, VISION_DIM + JOINT_DIM, cfg.units, cfg.layers)

    def forward(self, inputs: torch.Tensor, lengths: torch.Tensor) -> torch.Tensor:
        k = self.stride                                         # inputs (B, T, 35), lengths (B,)
        _, state = self.rnn(inputs[:, ::k], lstm_steps_of(lengths, k))   # (B, ceil(T/k), 35)
        return state_to_vector(state)                           # (B, 2 · layers · units)


class LanguageDecoder(nn.Module):
    """Generates w_1..w_4 from h, starting from <BOS>; softmax over the 23 words.

    (Over the lexicon's words, when it has more.)
    """

    def __init__(self, cfg: ModelConfig, lexicon: Lexicon = DEFAULT_LEXICON):
        super().__init__()
        self.words = words = lexicon.size                       # 23 for the paper's
        self.layers = cfg.layers
        self.init_state = nn.Linear(cfg.hidden, cfg.state_dim)   # initial state = W h + b
        self.rnn = make_recurrent(cfg.cell, words, cfg.units, cfg.layers)
        embedding_init_(self.rnn)
        self.out = nn.Linear(cfg.units, words)

    def forward(self, h: torch.Tensor, target: torch.Tensor | None = None, steps: int = 4,
                feedback: str = "greedy") -> torch.Tensor:
        """Logits (B, steps, 23).

        ``target`` given: teacher forcing, the inputs are <BOS> and the target's
        words (one fused pass). Otherwise autoregressive: ``feedback="greedy"``
        feeds the argmax word back, ``"soft"`` the softmax (authors' code).
        """
        state = vector_to_state(self.init_state(h), self.layers)
        bos = h.new_zeros(h.shape[0], 1, self.words)
        bos[..., 0] = 1.0
        if target is not None:
            words = nn.functional.one_hot(target[:, :-1], self.words).float()
            x = torch.cat([bos, words], 1)                      # (B, 4, words)
            y, _ = self.rnn(x, None, state)
            return self.out(y)
        x, logits = bos[:, 0], []
        for _ in range(steps):
            y, state = self.rnn.step(x, state)
            logit = self.out(y)                                 # (B, words)
            logits.append(logit)
            x = (logit.softmax(-1) if feedback == "soft"
                 else nn.functional.one_hot(logit.argmax(-1), self.words).float())
        return torch.stack(logits, 1)


class ActionDecoder(nn.Module):
    """Generates joints step by step: input [v_t; ĵ_t], output ĵ_{t+1} = tanh(W y_t + b).

    The visual features v_t are the recorded ones at every step (teacher-forced,
    as in the paper); the joints are the decoder's own previous predictions (the
    paper's) or the start joints (``joint_feedback="start"``).

    One step at a time, e.g. to drive a robot that renders v_t as it moves
    (:mod:`pgae_lite.robot.closedloop`)::

        state = decoder.begin(h)
        j = start                                   # ĵ_0 = the start joints
        for v_t in vision:                          # v_0, v_1, ...
            j, state = decoder.step(state, v_t, j, start)   # ĵ_{t+1}
    """

    def __init__(self, cfg: ModelConfig):
        super().__init__()
        if cfg.joint_feedback not in ("predicted", "start"):
            raise ValueError(f"unknown joint_feedback {cfg.joint_feedback!r}; the options are: predicted, start")
        self.layers = cfg.layers
        self.feedback = cfg.joint_feedback
        self.stride = cfg.time_stride                           # poses written per step
        self.init_state = nn.Linear(cfg.hidden, cfg.state_dim)
        self.rnn = make_recurrent(cfg.cell, VISION_DIM + JOINT_DIM, cfg.units, cfg.layers)
        self.out = nn.Linear(cfg.units, JOINT_DIM * self.stride)

    def begin(self, h: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """The LSTM's initial state (h, c), each (layers, B, units), from the shared representation h: W h + b."""
        return vector_to_state(self.init_state(h), self.layers)

    def step(self, state: tuple[torch.Tensor, torch.Tensor], v_t: torch.Tensor, j_t: torch.Tensor,
             start: torch.Tensor) -> tuple[torch.Tensor, tuple[torch.Tensor, torch.Tensor]]:
        """One step: v_t (B, 30), ĵ_t (B, 5), start joints (B, 5) -> ĵ_{t+1} (B, 5) and the new state.

        With ``joint_feedback="start"`` the decoder reads ``start`` in place of ĵ_t. With
        ``time_stride`` k > 1 a step writes the next k poses, ĵ_{t+1} .. ĵ_{t+k}, side by
        side (B, 5k); ``j_t`` may be such a step's output (its last pose is ĵ_t).
        """
        joints_in = start if self.feedback == "start" else j_t[:, -JOINT_DIM:]
        y, state = self.rnn.step(torch.cat([v_t, joints_in], 1), state)
        return torch.tanh(self.out(y)), state

    def forward(self, h: torch.Tensor, vision: torch.Tensor, start: torch.Tensor,
                steps: torch.Tensor | None = None) -> torch.Tensor:
        """vision (B, S, 30), start (B, 5) -> joints of steps 1..S (B, S, 5).

        ``steps`` (B,), if given, is how many steps each sample needs: a free-running
        decoder then stops computing a sample after its last step (outputs 0 there).
        With ``time_stride`` k > 1 it reads v_0, v_k, v_2k, ... and writes k poses
        after each (:meth:`step`).
        """
        k, S = self.stride, vision.shape[1]
        run = self._fused if self.feedback == "start" else self._free_running
        lstm_steps = None if steps is None else lstm_steps_of(steps, k)
        poses = run(self.begin(h), vision[:, ::k], start, lstm_steps)         # (B, ceil(S/k), 5k)
        joints = poses.reshape(len(h), -1, JOINT_DIM)[:, :S]                  # (B, S, 5)
        if steps is not None:                                                 # 0 past a sample's last step
            joints = joints * (torch.arange(S, device=vision.device) < steps[:, None])[..., None]
        return joints

    def _fused(self, state, vision: torch.Tensor, start: torch.Tensor, steps: torch.Tensor | None) -> torch.Tensor:
        # Deviation from paper: the decoder reads the start joints at every step instead of
        # its own predictions, so its small errors cannot feed back and grow, and training
        # and test run the same single fused pass over all steps.
        prev = start[:, None].expand(-1, vision.shape[1], -1)                 # (B, S, 5)
        y, _ = self.rnn(torch.cat([vision, prev], 2), steps, state)          # each sample for its own steps
        return torch.tanh(self.out(y))                                        # (B, S, 5k)

    def _free_running(self, state, vision: torch.Tensor, start: torch.Tensor,
                      steps: torch.Tensor | None) -> torch.Tensor:
        # The paper's decoder: ĵ_{t+1} = step(v_t, ĵ_t), one step at a time, every sample until the longest one
        # ends (forward sets what comes after a sample's own last step to 0).
        S = vision.shape[1]
        longest = S if steps is None else int(steps.max())
        j, outs = start, []
        for v_t in vision[:, :longest].unbind(1):                 # longest x (B, 30)
            j, state = self.step(state, v_t, j, start)            # ĵ_{t+1}, (B, 5k)
            outs.append(j)
        joints = torch.stack(outs, 1)                             # (B, longest, 5k)
        return nn.functional.pad(joints, (0, 0, 0, S - longest))  # (B, S, 5k)


def build_language_encoder(cfg: ModelConfig, lexicon: Lexicon = DEFAULT_LEXICON) -> LanguageEncoderBase:
    """The language encoder ``cfg`` names: PGAE's LSTM, or what its ``language`` part builds (a pretrained
    transformer: :mod:`pgae_lite.bert`, :mod:`pgae_lite.freeform`)."""
    return LanguageEncoder(cfg, lexicon) if cfg.language is None else cfg.language.build(lexicon)


class PGAE(LearnsFromSignals, nn.Module):
    """The whole model: two encoders, the GMU, two decoders.

    ``lexicon``: the words it reads and writes (default: the paper's 23). The language encoder is
    the LSTM, or the pretrained one ``cfg.language`` builds (PGAE-BERT). What it learns from and how
    it is trained: :class:`~pgae_lite.model.loss.LearnsFromSignals`.
    """

    def __init__(self, cfg: ModelConfig | None = None, lexicon: Lexicon = DEFAULT_LEXICON):
        super().__init__()
        self.cfg = cfg or ModelConfig()
        if self.cfg.crossmodal is not None or self.cfg.binding is not None:
            raise ValueError("PGAE joins its two encoders in a GMU; a ModelConfig with crossmodal (PTAE) or binding "
                             "(PRAE, PVAE) builds another model: pgae_lite.model.build.build_model(cfg)")
        self.lexicon = lexicon
        self.register_buffer("word_weights", word_weights(lexicon), persistent=False)   # the loss's, (words,)
        # built here, in this order, for the same weights under a seed
        self.language_encoder = build_language_encoder(self.cfg, lexicon)
        self.action_encoder = ActionEncoder(self.cfg)
        self.gmu = GatedMultimodalUnit(self.cfg.state_dim, self.language_encoder.output_dim, self.cfg.hidden,
                                       normalise_action=self.cfg.gmu_norm)
        self.language_decoder = LanguageDecoder(self.cfg, lexicon)
        self.action_decoder = ActionDecoder(self.cfg)
        # Deviation from paper: a plan head on h, trained to predict keyframes of the motion (plan.py).
        self.plan_head = (PlanHead(self.cfg.hidden, self.cfg.plan_keyframes, self.cfg.units)
                          if self.cfg.plan_keyframes else None)

    def encode(self, batch: SignalBatch, language: torch.Tensor | None = None) -> tuple[torch.Tensor, torch.Tensor]:
        """Shared representation h and GMU gate z, each (B, hidden).

        ``language`` (B, D), if given, replaces the language encoder's output, e.g. free text
        through PGAE-BERT: ``model.language_encoder.encode_texts(["execute please push ..."])``.
        """
        if language is None:
            f_lang = self.language_encoder(batch.lang_tokens, batch.lang_lengths)
        else:
            f_lang = language
            if f_lang.shape != (len(batch.signal), self.language_encoder.output_dim):
                raise ValueError(f"language features must be (batch, {self.language_encoder.output_dim}) = "
                                 f"{(len(batch.signal), self.language_encoder.output_dim)}; got {tuple(f_lang.shape)}")
        f_act = self.action_encoder(batch.action_input, batch.action_lengths)
        return self.gmu(f_act, f_lang)

    def forward(self, batch: SignalBatch, teacher_language: bool = False, feedback: str = "greedy",
                language: torch.Tensor | None = None) -> dict[str, torch.Tensor]:
        """Returns ``logits`` (B, 4, 23), ``joints`` (B, T-1, 5), ``h`` and ``gate`` (B, hidden),
        and ``plan`` (B, K x 5) when the model has a plan head.

        ``teacher_language``: the language decoder reads the target words (training).
        ``language`` (B, D): precomputed language features in place of the encoder's (see :meth:`encode`).
        """
        h, z = self.encode(batch, language)
        logits = self.language_decoder(
            h, batch.lang_target if teacher_language else None, feedback=feedback)
        joints = self.action_decoder(h, batch.dec_vision, batch.start_joints, steps=batch.joint_mask.sum(1))
        out = {"logits": logits, "joints": joints, "h": h, "gate": z}
        if self.plan_head is not None:
            out["plan"] = self.plan_head(h)                     # keyframes of the motion h plans
        return out


def count_parameters(model: nn.Module) -> int:
    """Number of trainable parameters."""
    return sum(p.numel() for p in model.parameters() if p.requires_grad)
