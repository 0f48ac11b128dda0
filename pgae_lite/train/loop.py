"""Training PGAE: the loss, the loop, checkpoints (paper Sec. 3, "Loss Function", and Sec. 4).

    L = α · weighted cross-entropy(words) + β · MSE(joints)

The word weights counter word frequency (``<BOS/EOS>`` is in every
description, a colour word in one of six); both terms are averaged over the
valid steps only. Training is deterministic under a seed (bit for bit on the
same kind of device: on the CPU it runs on a fixed number of torch threads,
:func:`~pgae_lite.util.storage.training_threads`, since a 1-thread and a 2-thread run
round sums differently and drift apart), runs on CUDA when present
(else the CPU), and resumes from its last checkpoint after an interruption.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch
from torch import nn
from tqdm.auto import tqdm

from pgae_lite.config import Profile, get_profile
from pgae_lite.train.config import saved_model_config
from pgae_lite.data.dataset import JOINT_DIM, Normaliser, PGAEDataset
from pgae_lite.util.errors import PGAELiteError
from pgae_lite.world.words import SIGNALS, word_weights
from pgae_lite.model.pgae import PGAE
from pgae_lite.model.plan import plan_loss, plan_targets
from pgae_lite.model.signals import EXECUTE, SignalBatch, make_batch, sample_signals
from pgae_lite.util.storage import (CheckpointMismatchError, default_device, folder_lock, load_torch,
                    save_torch, training_threads)

CHECKPOINT = "checkpoint.pt"
#: What every checkpoint written by :func:`save_checkpoint` holds.
CHECKPOINT_KEYS = ("model", "optimiser", "generator", "torch_rng", "epoch", "history",
                   "profile", "normaliser", "seconds")


def pgae_loss(out: dict[str, torch.Tensor], batch: SignalBatch, weights: torch.Tensor,
              alpha: float = 1.0, beta: float = 1.0) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Total, language and action loss of one batch.

    language = Σ w[y] · CE(logits, y) / Σ mask  over valid words
    action   = Σ (ĵ − j)² / (5 · Σ mask)        over valid steps
    """
    ce = nn.functional.cross_entropy(out["logits"].transpose(1, 2), batch.lang_target,
                                     reduction="none")                      # (B, 4)
    m = batch.lang_mask.float()
    lang = (weights[batch.lang_target] * ce * m).sum() / m.sum()
    jm = batch.joint_mask.float()[..., None]                                # (B, T-1, 1)
    act = ((out["joints"] - batch.joint_target) ** 2 * jm).sum() / (jm.sum() * out["joints"].shape[-1])
    return alpha * lang + beta * act, lang, act


def lr_factor(step: int, total: int, warmup: float, schedule: str) -> float:
    """Learning-rate multiplier: linear warm-up, then cosine decay to 0 (or constant)."""
    warm = int(warmup * total)
    if step < warm:
        return (step + 1) / warm
    if schedule == "constant":
        return 1.0
    progress = (step - warm) / max(1, total - warm)
    return 0.5 * (1.0 + math.cos(math.pi * min(1.0, progress)))


def parameter_groups(model: nn.Module) -> list[dict]:
    """The optimiser's groups: every weight at the recipe's rate, except those of a module with an
    ``lr_scale`` (the tuned top layer, tuned_layer.py): lr · lr_scale, no weight decay."""
    scaled = [m for m in model.modules() if hasattr(m, "lr_scale")]
    own = {id(p) for m in scaled for p in m.parameters()}
    groups = [{"params": [p for p in model.parameters() if id(p) not in own], "lr_scale": 1.0}]
    groups += [{"params": list(m.parameters()), "lr_scale": m.lr_scale, "weight_decay": 0.0} for m in scaled]
    return groups


def batch_indices(lengths: torch.Tensor, batch_size: int, generator: torch.Generator,
                  by_length: bool = True) -> list[torch.Tensor]:
    """One epoch's batches of sample indices, in random order.

    ``by_length``: every batch holds samples of one length (slow or fast). Deviation from paper
    (batches of any samples): a batch's LSTMs then run one group of equal lengths instead of two,
    which measured 13% less time per epoch (A2, "Where the time goes").
    """
    order = torch.randperm(len(lengths), generator=generator)
    if not by_length:
        return list(order.split(batch_size))
    groups = [order[lengths[order] == n] for n in lengths.unique()]      # each in random order
    batches = [b for g in groups for b in g.split(batch_size)]
    return [batches[i] for i in torch.randperm(len(batches), generator=generator)]


@dataclass
class Trained:
    """What :func:`train` returns: the model, its normaliser, the history and the wall time."""

    model: PGAE
    normaliser: Normaliser
    history: list[dict]
    profile: Profile
    seconds: float


def add_input_noise(action_input: torch.Tensor, std: float, joint_std: float | None = None) -> torch.Tensor:
    """``action_input`` (B, T, 30 + 5) plus Gaussian noise: ``std`` on the visual features, ``joint_std``
    on the joints (``None``: ``std`` on both)."""
    noise = torch.randn_like(action_input)
    if joint_std is None:
        return action_input + std * noise
    scale = torch.full((action_input.shape[-1],), std, device=action_input.device)
    scale[-JOINT_DIM:] = joint_std                                        # the last 5 channels are joints
    return action_input + scale * noise


class DataMismatchError(PGAELiteError, ValueError):
    """A checkpoint is used with data (visual features) other than those it was trained on."""


class NonFiniteLossError(PGAELiteError, FloatingPointError):
    """The training loss became NaN or infinite: the run stops, nothing is saved."""


def _training_split(dataset: PGAEDataset, max_samples: int | None = None) -> PGAEDataset:
    """The samples a training run learns from: the training split, or its first ``max_samples``."""
    train_set = dataset.split("train")
    return train_set.subset(slice(0, max_samples)) if max_samples else train_set


def train(dataset: PGAEDataset, profile: Profile | str | None = None, out_dir: str | Path | None = None,
          device: torch.device | str | None = None, progress: bool = True,
          model: PGAE | None = None, callback=None) -> Trained:
    """Train PGAE on the training split of ``dataset``.

    With ``out_dir`` a checkpoint is written there every
    ``checkpoint_every`` epochs and at the end (atomically); a later call with
    the same ``out_dir`` and profile resumes from it, and one whose training
    finished returns at once. While it runs, a lock file in ``out_dir`` makes a
    second run there fail (:class:`~pgae_lite.util.storage.FolderBusyError`).
    ``callback(epoch, model, record)``, if given, is called after every epoch
    (e.g. to evaluate along the way). A NaN or infinite loss stops the run
    (:class:`NonFiniteLossError`, naming the epoch and the batch).
    """
    device = torch.device(device) if device else default_device()
    args = (dataset, profile, out_dir, device, progress, model, callback)
    with training_threads(device):   # on the CPU a fixed thread count: the same model on any machine
        if out_dir is None:
            return _train(*args)
        with folder_lock(out_dir):
            return _train(*args)


def _train(dataset: PGAEDataset, profile: Profile | str | None,
           out_dir: str | Path | None, device: torch.device,
           progress: bool, model: PGAE | None, callback) -> Trained:
    profile = profile if isinstance(profile, Profile) else get_profile(profile)
    cfg = profile.train
    cfg.__post_init__()              # checked again: a field may have been set since
    train_set = _training_split(dataset, cfg.max_train_samples)
    normaliser = Normaliser.fit(train_set, cfg.vision_scaling)
    data = normaliser.tensors(train_set, device)

    torch.manual_seed(cfg.seed)
    model = (model or PGAE(profile.model)).to(device)
    plans = None                     # each training sample's plan target (plan.py), if the model has a plan head
    if model.plan_head is not None and cfg.plan_weight:
        plans = plan_targets(data["joints"], data["lengths"], torch.as_tensor(train_set.pattern, device=device),
                             model.plan_head.keyframes)
    # fused: one kernel for all parameters (measured: 0.55 ms per step against 3.2 ms; benchmarks/profile_epoch.py)
    fused = dict(fused=True) if device.type in ("cpu", "cuda") else {}
    groups = parameter_groups(model)
    optimiser = (torch.optim.AdamW(groups, lr=cfg.lr, weight_decay=cfg.weight_decay, **fused)
                 if cfg.weight_decay else torch.optim.Adam(groups, lr=cfg.lr, **fused))
    gen = torch.Generator().manual_seed(cfg.seed)  # signals, descriptions, views, shuffling
    n = len(train_set)
    lengths = data["lengths"].cpu()
    batches = len(batch_indices(lengths, cfg.batch_size, torch.Generator(), cfg.length_batches))
    total = cfg.epochs * batches
    start_epoch, history, elapsed = 0, [], 0.0

    ckpt_path = Path(out_dir) / CHECKPOINT if out_dir else None
    if ckpt_path and ckpt_path.exists():
        ckpt = load_checkpoint(ckpt_path)
        if ckpt["profile"] != profile.to_dict():
            raise CheckpointMismatchError(
                f"{ckpt_path} was trained with a different profile or seed; use another output "
                "folder, or delete the checkpoint to start again")
        _check_trained_on(ckpt, normaliser.state_dict(), ckpt_path, dataset.source)
        model.load_state_dict(ckpt["model"])
        optimiser.load_state_dict(ckpt["optimiser"])
        gen.set_state(ckpt["generator"])
        torch.set_rng_state(ckpt["torch_rng"])
        start_epoch, history, elapsed = ckpt["epoch"], ckpt["history"], ckpt["seconds"]

    weights = word_weights(getattr(model, "lexicon", None)).to(device)   # model's words
    t0 = time.perf_counter() - elapsed
    bank = None                             # its encoding time counts as training time
    if cfg.phrasings:                       # free-form language (phrasing_bank.py), PGAE-BERT only
        from pgae_lite.bert.phrase_lexicon import training_lexicon
        from pgae_lite.bert.phrasing_bank import PhrasingBank
        bank = PhrasingBank(model.language_encoder, cfg.phrasings, cfg.seed, training_lexicon(cfg.phrasing_words),
                            cfg.phrasing_signals, cfg.phrasing_prob)
        if hasattr(model.language_encoder, "word_lookup"):   # words never trained on: WordNet first
            from pgae_lite.bert.word_lookup import WordLookup
            model.language_encoder.word_lookup = WordLookup(training_lexicon(cfg.phrasing_words), bank.texts)
    bar = tqdm(range(start_epoch, cfg.epochs), desc=f"PGAE ({profile.name})", disable=not progress,
               initial=start_epoch, total=cfg.epochs)
    for epoch in bar:
        model.train()
        epoch_batches = batch_indices(lengths, cfg.batch_size, gen, cfg.length_batches)
        sums = torch.zeros(3)
        gate_sum, gate_n = torch.zeros(len(SIGNALS)), torch.zeros(len(SIGNALS))
        for b in range(batches):
            step = epoch * batches + b
            for g in optimiser.param_groups:
                g["lr"] = cfg.lr * lr_factor(step, total, cfg.warmup, cfg.schedule) * g.get("lr_scale", 1.0)
            index = epoch_batches[b]
            size = len(index)
            signal = sample_signals(size, gen, cfg.signals_per_sample, cfg.signal_probs)
            alternative = torch.randint(8, (size,), generator=gen)
            opposite = torch.rand(size, generator=gen) < cfg.opposite_prob
            opposite &= signal != EXECUTE  # execute shows no action to the encoder
            batch = make_batch(data, index, signal, alternative, opposite)
            if cfg.input_noise or cfg.joint_input_noise:  # regularises what the action encoder reads (model units)
                batch.action_input = add_input_noise(batch.action_input, cfg.input_noise, cfg.joint_input_noise)
            language = None if bank is None else bank.features(model, batch, gen, step)
            out = model(batch, teacher_language=cfg.teacher_language,
                        feedback="greedy" if cfg.teacher_language else "soft", language=language)
            loss, lang, act = pgae_loss(out, batch, weights, cfg.language_weight, cfg.action_weight)
            if plans is not None:      # Deviation from paper: L += β γ L_plan (plan.py)
                planned = plan_loss(out["plan"], plans[index.to(device)], batch.signal)
                loss = loss + cfg.action_weight * cfg.plan_weight * planned
            optimiser.zero_grad(set_to_none=True)
            loss.backward()
            if cfg.clip:
                nn.utils.clip_grad_norm_(model.parameters(), cfg.clip)
            optimiser.step()
            losses = torch.tensor([loss.item(), lang.item(), act.item()])
            if not torch.isfinite(losses).all():
                _stop(losses, epoch, b, batches, signal)
            sums += losses * size
            z = out["gate"].detach().float().mean(1).cpu()   # float: also under autocast
            gate_sum.index_add_(0, signal, z)
            gate_n.index_add_(0, signal, torch.ones(size))
        loss, lang, act = (sums / n).tolist()
        gates = (gate_sum / gate_n.clamp(min=1)).tolist()
        history.append({"epoch": epoch + 1, "loss": loss, "language_loss": lang, "action_loss": act,
                        "lr": optimiser.param_groups[0]["lr"],
                        "gate": {s: g for s, g, k in zip(SIGNALS, gates, gate_n) if k > 0}})
        bar.set_postfix(loss=f"{loss:.4f}", lang=f"{lang:.4f}", act=f"{act:.5f}")
        if callback is not None:
            callback(epoch + 1, model, history[-1])
            model.train()
        last = epoch + 1 == cfg.epochs
        if ckpt_path and (last or (epoch + 1) % cfg.checkpoint_every == 0):
            save_checkpoint(ckpt_path, model, optimiser, gen, epoch + 1, history, profile, normaliser,
                            time.perf_counter() - t0)
    model.eval()
    return Trained(model, normaliser, history, profile, time.perf_counter() - t0)


def _stop(losses: torch.Tensor, epoch: int, batch: int, batches: int,
          signal: torch.Tensor) -> None:
    """Raise :class:`NonFiniteLossError` for a batch whose loss is NaN or infinite."""
    total, lang, act = losses.tolist()
    signals = ", ".join(SIGNALS[i] for i in sorted(set(signal.tolist())))
    raise NonFiniteLossError(
        f"training stopped: the loss is {total} (language {lang}, action {act}) at "
        f"epoch {epoch + 1}, batch {batch + 1} of {batches} (signals {signals}); look "
        "for extreme values in the data, or lower the learning rate")


def save_checkpoint(path: Path, model: PGAE, optimiser: torch.optim.Optimizer, gen: torch.Generator,
                    epoch: int, history: list[dict], profile: Profile, normaliser: Normaliser,
                    seconds: float) -> None:
    """Write a checkpoint atomically (a crash mid-write never leaves a broken file).

    A write that fails (a full disk, a read-only folder) raises
    :class:`~pgae_lite.util.storage.OutputError` naming the file; the old checkpoint stays.
    """
    save_torch({"model": model.state_dict(), "optimiser": optimiser.state_dict(),
                "generator": gen.get_state(), "torch_rng": torch.get_rng_state(),
                "epoch": epoch, "history": history, "profile": profile.to_dict(),
                "normaliser": normaliser.state_dict(), "seconds": seconds}, path)


def load_checkpoint(path: str | Path) -> dict:
    """Read a checkpoint safely (``weights_only=True``: tensors and plain data only).

    An empty, truncated or foreign file raises
    :class:`~pgae_lite.util.storage.CorruptCheckpointError` naming it.
    """
    return load_torch(path, CHECKPOINT_KEYS)


def _same_numbers(a: list, b: list) -> bool:
    """Two (nested) lists of floats hold the same numbers, up to rounding."""
    a, b = (np.hstack([np.ravel(x) for x in v]).astype(float) for v in (a, b))
    return a.shape == b.shape and bool(np.allclose(a, b))


def _check_trained_on(ckpt: dict, fitted: dict, path: str | Path, source: str = "") -> None:
    """Raise :class:`DataMismatchError` unless ``fitted`` (a normaliser's state, fitted on the
    training samples of the data at hand) equals the one saved in ``ckpt``."""
    saved = ckpt["normaliser"]
    differ = [k for k in saved if k not in fitted or not _same_numbers(fitted[k], saved[k])]
    if differ:
        raise DataMismatchError(
            f"{path} was not trained on this data ({source or 'dataset'}): the statistics of its training "
            f"samples ({', '.join(differ)}) differ from those saved with the model. Use the data it was "
            "trained on: for our simulated data the same cache (PGAE_LITE_CACHE), since the visual features "
            "come from the cache's CAE and a CAE trained elsewhere (or with another number of threads) gives "
            "other features; or train the model again on this data (another output folder).")


def load_model(path: str | Path, device: torch.device | str | None = None,
               dataset: PGAEDataset | None = None) -> tuple[PGAE, Normaliser, dict]:
    """Model (in eval mode), normaliser and the checkpoint's other contents.

    With ``dataset``, first check that the model was trained on it: the
    normaliser fitted on its training samples must equal the one saved. The
    visual features come from a CAE, and two CAEs (e.g. trained with another
    number of threads, in another cache) give different features: a model fed
    another CAE's features produces nonsense without any error, so this
    raises :class:`DataMismatchError` instead.
    """
    ckpt = load_torch(path, ("model", "profile", "normaliser"))
    if dataset is not None:
        cfg = ckpt["profile"]["train"]
        fitted = Normaliser.fit(_training_split(dataset, cfg.get("max_train_samples")),
                                cfg.get("vision_scaling", "global")).state_dict()
        _check_trained_on(ckpt, fitted, path, dataset.source)
    model = PGAE(saved_model_config(ckpt["profile"], path))
    model.load_state_dict(ckpt["model"])
    model.to(device or default_device()).eval()
    return model, Normaliser.from_state_dict(ckpt["normaliser"]), ckpt


__all__ = ["train", "pgae_loss", "DataMismatchError", "NonFiniteLossError",
           "Trained", "load_model", "load_checkpoint",
           "save_checkpoint", "lr_factor"]
