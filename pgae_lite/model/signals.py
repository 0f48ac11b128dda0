"""The five signals: what each task feeds the encoders and expects from the decoders.

Paper, Sec. 3 ("Signals") and Table 1's tasks. One model does every task; the
signal word prepended to the language input picks it::

    | signal          | language in          | action in     | language target | action target       |
    |-----------------|----------------------|---------------|-----------------|---------------------|
    | describe        | signal + <EOS>       | whole         | description     | final joints, held  |
    | execute         | signal + description | first step    | <EOS>           | whole joint sequence|
    | repeat action   | signal + <EOS>       | whole         | <EOS>           | whole joint sequence|
    | repeat both     | signal + description | whole         | description     | whole joint sequence|
    | repeat language | signal + description | first step    | description     | first joints, held  |

:func:`make_batch` builds all of it for a batch in which every sample may
carry its own signal, description alternative and view.
"""
from __future__ import annotations

from dataclasses import dataclass

import torch

from pgae_lite.world.words import SIGNALS, VOCABULARY, normalise_signal

DESCRIBE, EXECUTE, REPEAT_ACTION, REPEAT_BOTH, REPEAT_LANGUAGE = range(5)
#: Authors' sampling: describe 1/3, execute 1/3, each repeat signal 1/9.
SIGNAL_PROBS = (3 / 9, 3 / 9, 1 / 9, 1 / 9, 1 / 9)
LANG_IN = (False, True, False, True, True)       # does the signal feed the description in?
ACTION_IN = (True, False, True, True, False)     # does it feed the whole action in?
LANG_OUT = (True, False, False, True, True)      # must it produce the description?
EOS = 0
SIGNAL_TOKEN = len(VOCABULARY)                   # signal s is input token 23 + s
# (a PGAE with a lexicon of V words moves it to V + s itself: pgae.LanguageEncoder)


@dataclass
class SignalBatch:
    """Encoder inputs and decoder targets for one batch (B samples, T steps)."""

    signal: torch.Tensor          # (B,) signal index
    lang_tokens: torch.Tensor     # (B, 5) tokens in the 28-d input space: signal, words..., <EOS>
    lang_lengths: torch.Tensor    # (B,) 5 with a description, 2 without
    action_input: torch.Tensor    # (B, T, 35) [vision; joints] per step
    action_lengths: torch.Tensor  # (B,) sample length, or 1 (first step only)
    lang_target: torch.Tensor     # (B, 4) words w1 w2 w3 <EOS> (or <EOS> alone, masked)
    lang_mask: torch.Tensor       # (B, 4) bool
    dec_vision: torch.Tensor      # (B, T-1, 30) vision fed to the action decoder
    start_joints: torch.Tensor    # (B, 5) joints at step 0 of the output
    joint_target: torch.Tensor    # (B, T-1, 5) joints of steps 1..T-1
    joint_mask: torch.Tensor      # (B, T-1) bool, valid steps
    plan_target: torch.Tensor | None = None   # (B, K x 5) in training, with a plan head (model/loss.py)


def signal_ids(names: list[str] | str, batch: int | None = None) -> torch.Tensor:
    """Signal names -> indices; one name with ``batch`` repeats it."""
    if isinstance(names, str):
        return torch.full((batch or 1,), SIGNALS.index(normalise_signal(names)), dtype=torch.long)
    return torch.tensor([SIGNALS.index(normalise_signal(n)) for n in names])


def make_batch(data: dict[str, torch.Tensor], index: torch.Tensor, signal: torch.Tensor,
               alternative: torch.Tensor, opposite: torch.Tensor | None = None) -> SignalBatch:
    """Build a :class:`SignalBatch` from normalised dataset tensors.

    ``index`` picks samples, ``signal`` (B,) their signals, ``alternative``
    (B,) which of the 8 descriptions, ``opposite`` (B,) bool whether the
    action encoder sees the opposite agent (its vision, and NICO's own first
    joints held, since NICO does not move).
    """
    dev = data["joints"].device
    index, signal, alternative = index.to(dev), signal.to(dev), alternative.to(dev)
    B = len(index)
    rows = torch.arange(B, device=dev)
    joints, vision = data["joints"][index], data["vision"][index]           # (B, T, 5), (B, T, 30)
    lengths = data["lengths"][index]                                         # (B,)
    T = joints.shape[1]
    words = data["descriptions"][index, alternative]                         # (B, 3)
    opposite = torch.zeros(B, dtype=torch.bool, device=dev) if opposite is None else opposite.to(dev)

    def table(column: tuple[bool, ...]) -> torch.Tensor:                     # per-sample lookup, (B,)
        return torch.tensor(column, device=dev)[signal]
    lang_in, action_in, lang_out = table(LANG_IN), table(ACTION_IN), table(LANG_OUT)

    # Language encoder: [signal, w1, w2, w3, <EOS>] or [signal, <EOS>] (then padding).
    eos = torch.full((B, 1), EOS, device=dev)
    with_words = torch.cat([words, eos], 1)                                  # (B, 4)
    without = torch.full((B, 4), EOS, device=dev)                            # (B, 4)
    lang_tokens = torch.cat([(SIGNAL_TOKEN + signal)[:, None],
                             torch.where(lang_in[:, None], with_words, without)], 1)  # (B, 5)
    lang_lengths = torch.where(lang_in, 5, 2)

    # Action encoder: the whole sequence, or the first step only.
    enc_vision = torch.where(opposite[:, None, None], data["vision_opposite"][index], vision)
    enc_joints = torch.where(opposite[:, None, None], joints[:, :1].expand_as(joints), joints)
    action_input = torch.cat([enc_vision, enc_joints], 2)                   # (B, T, 35)
    action_lengths = torch.where(action_in, lengths, torch.ones_like(lengths))

    # Language decoder target: the description, or <EOS> alone.
    lang_target = torch.where(lang_out[:, None], with_words, torch.full_like(with_words, EOS))
    lang_mask = torch.where(lang_out[:, None], torch.ones(B, 4, dtype=torch.bool, device=dev),
                            torch.arange(4, device=dev)[None] < 1)

    # Action decoder: recorded sequence, or one pose held (describe: final; repeat language,
    # or describing the opposite agent: first).
    last = lengths - 1
    hold_last = (signal == DESCRIBE) & ~opposite
    hold_first = (signal == REPEAT_LANGUAGE) | ((signal == DESCRIBE) & opposite)
    held_step = torch.where(hold_last, last, torch.zeros_like(last))         # (B,)
    held_joints = joints[rows, held_step][:, None].expand(B, T, -1)          # (B, T, 5)
    held_vision = vision[rows, held_step][:, None].expand(B, T, -1)          # (B, T, 30)
    hold = (hold_last | hold_first)[:, None, None]
    out_joints = torch.where(hold, held_joints, joints)                      # (B, T, 5)
    dec_vision = torch.where(hold, held_vision, vision)[:, :-1]              # (B, T-1, 30)
    joint_mask = torch.arange(1, T, device=dev)[None] < lengths[:, None]     # (B, T-1)
    return SignalBatch(signal, lang_tokens, lang_lengths, action_input, action_lengths,
                       lang_target, lang_mask, dec_vision, out_joints[:, 0], out_joints[:, 1:],
                       joint_mask)


def sample_signals(batch: int, generator: torch.Generator, per_sample: bool = True,
                   probs: tuple[float, ...] = SIGNAL_PROBS) -> torch.Tensor:
    """Draw signals: one per sample (default), or one for the whole batch (the authors')."""
    p = torch.tensor(probs)
    if per_sample:
        return torch.multinomial(p, batch, replacement=True, generator=generator)
    return torch.multinomial(p, 1, generator=generator).expand(batch).clone()
