"""Training PGAE: the loop, as a short sequence of named steps (paper Sec. 3, "Loss Function", and Sec. 4).

    setup -> resume -> for each epoch, for each batch: batch -> language features -> step
          -> record the epoch -> checkpoint

Training is deterministic under a seed (bit for bit on the same kind of device: on the CPU it
runs on a fixed number of torch threads, :func:`~pgae_lite.util.storage.training_threads`, since a
1-thread and a 2-thread run round sums differently and drift apart), runs on CUDA when present
(else the CPU), and resumes from its last checkpoint after an interruption
(:mod:`pgae_lite.train.checkpoint`). The loss is :mod:`pgae_lite.train.loss`'s; a training on
phrasings reads them from the bank the free-form code sets up
(:func:`pgae_lite.bert.phrasing_bank.for_training`).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import torch
from torch import nn
from tqdm.auto import tqdm

from pgae_lite.bert.encoders import build_pgae
from pgae_lite.bert.phrasing_bank import for_training
from pgae_lite.data.dataset import Normaliser, PGAEDataset
from pgae_lite.model.pgae import PGAE
from pgae_lite.model.plan import plan_loss, plan_targets
from pgae_lite.model.signals import EXECUTE, make_batch
from pgae_lite.train.checkpoint import CHECKPOINT, check_trained_on, load_checkpoint, save_checkpoint, training_split
from pgae_lite.train.loss import add_input_noise, lr_factor, parameter_groups, pgae_loss
from pgae_lite.train.supervision import draw_signals, labelled_samples
from pgae_lite.util.errors import PGAELiteError
from pgae_lite.util.storage import CheckpointMismatchError, default_device, folder_lock, training_threads
from pgae_lite.world.words import SIGNALS, word_weights


class NonFiniteLossError(PGAELiteError, FloatingPointError):
    """The training loss became NaN or infinite: the run stops, nothing is saved."""


@dataclass
class Trained:
    """What :func:`train` returns: the model, its normaliser, the history and the wall time."""

    model: PGAE
    normaliser: Normaliser
    history: list[dict]
    profile: object          # the pgae_lite.config.Profile it was trained with
    seconds: float


@dataclass
class Run:
    """What a training carries from step to step."""

    model: PGAE
    optimiser: torch.optim.Optimizer
    gen: torch.Generator                 # signals, descriptions, views, shuffling
    data: dict[str, torch.Tensor]        # the training samples, normalised, on the device
    lengths: torch.Tensor                # each sample's length, on the CPU (for the batches)
    plans: torch.Tensor | None           # each sample's plan target (model/plan.py), if the model has a head
    batches: int                         # per epoch
    labelled: torch.Tensor | None = None  # which samples are labelled (TrainConfig.labelled_share), on the CPU
    epoch: int = 0
    history: list[dict] = field(default_factory=list)
    elapsed: float = 0.0


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


def train(dataset: PGAEDataset, profile, out_dir: str | Path | None = None,
          device: torch.device | str | None = None, progress: bool = True,
          model: PGAE | None = None, callback=None, name: str = "PGAE") -> Trained:
    """Train PGAE on the training split of ``dataset`` with ``profile``'s recipe.

    ``profile``: a :class:`~pgae_lite.config.Profile` (``pgae_lite.config.get_profile(name)``).
    With ``out_dir`` a checkpoint is written there every
    ``checkpoint_every`` epochs and at the end (atomically); a later call with
    the same ``out_dir`` and profile resumes from it, and one whose training
    finished returns at once. While it runs, a lock file in ``out_dir`` makes a
    second run there fail (:class:`~pgae_lite.util.storage.FolderBusyError`).
    ``callback(epoch, model, record)``, if given, is called after every epoch
    (e.g. to evaluate along the way). A NaN or infinite loss stops the run
    (:class:`NonFiniteLossError`, naming the epoch and the batch). ``name``: the model's, on the progress
    bar, which shows only while there are epochs to train (a finished model loaded from ``out_dir`` shows none).
    """
    if not hasattr(profile, "to_dict") or not hasattr(profile, "train"):
        raise TypeError(f"train takes a Profile, e.g. pgae_lite.config.get_profile('book'); got {profile!r}")
    device = torch.device(device) if device else default_device()
    args = (dataset, profile, out_dir, device, progress, model, callback, name)
    with training_threads(device):   # on the CPU a fixed thread count: the same model on any machine
        if out_dir is None:
            return _train(*args)
        with folder_lock(out_dir):
            return _train(*args)


def _train(dataset: PGAEDataset, profile, out_dir: str | Path | None, device: torch.device,
           progress: bool, model: PGAE | None, callback, name: str) -> Trained:
    cfg = profile.train
    cfg.__post_init__()              # checked again: a field may have been set since
    train_set = training_split(dataset, cfg.max_train_samples)
    normaliser = Normaliser.fit(train_set, cfg.vision_scaling)
    run = _setup(train_set, normaliser, profile, device, model)
    ckpt_path = Path(out_dir) / CHECKPOINT if out_dir else None
    if ckpt_path and ckpt_path.exists():
        _resume(run, ckpt_path, profile, normaliser, dataset.source)
    weights = word_weights(getattr(run.model, "lexicon", None)).to(device)   # the model's words
    t0 = time.perf_counter() - run.elapsed
    bank = for_training(run.model.language_encoder, cfg)    # its encoding time counts as training time
    bar = tqdm(range(run.epoch, cfg.epochs), desc=f"{name} ({profile.name})", initial=run.epoch, total=cfg.epochs,
               disable=not progress or run.epoch >= cfg.epochs)          # nothing to train: no bar
    for epoch in bar:
        record = _epoch(run, cfg, epoch, weights, bank, device)
        bar.set_postfix_str(f"loss {record['loss']:.4f} (words {record['language_loss']:.4f}, "
                            f"joints {record['action_loss']:.5f})")
        if callback is not None:
            callback(epoch + 1, run.model, record)
            run.model.train()
        if ckpt_path and (epoch + 1 == cfg.epochs or (epoch + 1) % cfg.checkpoint_every == 0):
            save_checkpoint(ckpt_path, run.model, run.optimiser, run.gen, epoch + 1, run.history, profile,
                            normaliser, time.perf_counter() - t0)
    run.model.eval()
    return Trained(run.model, normaliser, run.history, profile, time.perf_counter() - t0)


def _setup(train_set: PGAEDataset, normaliser: Normaliser, profile, device: torch.device,
           model: PGAE | None) -> Run:
    """The model (seeded), its plan targets, the optimiser and the generator of a fresh run."""
    cfg = profile.train
    data = normaliser.tensors(train_set, device)
    torch.manual_seed(cfg.seed)
    model = (model or build_pgae(profile.model)).to(device)
    plans = None
    if model.plan_head is not None and cfg.plan_weight:
        plans = plan_targets(data["joints"], data["lengths"], torch.as_tensor(train_set.pattern, device=device),
                             model.plan_head.keyframes)
    # fused: one kernel for all parameters (measured: benchmarks/profile_epoch.py, A2)
    fused = dict(fused=True) if device.type in ("cpu", "cuda") else {}
    groups = parameter_groups(model)
    optimiser = (torch.optim.AdamW(groups, lr=cfg.lr, weight_decay=cfg.weight_decay, **fused)
                 if cfg.weight_decay else torch.optim.Adam(groups, lr=cfg.lr, **fused))
    gen = torch.Generator().manual_seed(cfg.seed)
    lengths = data["lengths"].cpu()
    batches = len(batch_indices(lengths, cfg.batch_size, torch.Generator(), cfg.length_batches))
    labelled = None if cfg.labelled_share is None else labelled_samples(len(lengths), cfg.labelled_share, cfg.seed)
    return Run(model, optimiser, gen, data, lengths, plans, batches, labelled)


def _resume(run: Run, path: Path, profile, normaliser: Normaliser, source: str) -> None:
    """Continue from the checkpoint at ``path``: the same recipe and data, or a clear error."""
    ckpt = load_checkpoint(path)
    if ckpt["profile"] != profile.to_dict():
        raise CheckpointMismatchError(
            f"{path} was trained with a different profile or seed; use another output "
            "folder, or delete the checkpoint to start again")
    check_trained_on(ckpt, normaliser.state_dict(), path, source)
    run.model.load_state_dict(ckpt["model"])
    run.optimiser.load_state_dict(ckpt["optimiser"])
    run.gen.set_state(ckpt["generator"])
    torch.set_rng_state(ckpt["torch_rng"])
    run.epoch, run.history, run.elapsed = ckpt["epoch"], ckpt["history"], ckpt["seconds"]


def _epoch(run: Run, cfg, epoch: int, weights: torch.Tensor, bank, device: torch.device) -> dict:
    """One epoch: every batch a step; returns (and keeps in the history) the epoch's record."""
    run.model.train()
    epoch_batches = batch_indices(run.lengths, cfg.batch_size, run.gen, cfg.length_batches)
    total = cfg.epochs * run.batches
    sums = torch.zeros(3)
    gate_sum, gate_n = torch.zeros(len(SIGNALS)), torch.zeros(len(SIGNALS))
    for b in range(run.batches):
        step = epoch * run.batches + b
        for g in run.optimiser.param_groups:
            g["lr"] = cfg.lr * lr_factor(step, total, cfg.warmup, cfg.schedule) * g.get("lr_scale", 1.0)
        index = epoch_batches[b]
        batch = _batch(run, cfg, index)
        language = None if bank is None else bank.features(run.model, batch, run.gen, step)
        out, losses = _step(run, cfg, batch, index, language, weights, device)
        if not torch.isfinite(losses).all():
            _stop(losses, epoch, b, run.batches, batch.signal)
        sums += losses * len(index)
        if "gate" in out:                                # PGAE's GMU (PTAE has none)
            z = out["gate"].detach().float().mean(1).cpu()   # float: also under autocast
            gate_sum.index_add_(0, batch.signal, z)
            gate_n.index_add_(0, batch.signal, torch.ones(len(index)))
    loss, lang, act = (sums / len(run.lengths)).tolist()
    gates = (gate_sum / gate_n.clamp(min=1)).tolist()
    run.history.append({"epoch": epoch + 1, "loss": loss, "language_loss": lang, "action_loss": act,
                        "lr": run.optimiser.param_groups[0]["lr"],
                        "gate": {s: g for s, g, k in zip(SIGNALS, gates, gate_n) if k > 0}})
    return run.history[-1]


def _batch(run: Run, cfg, index: torch.Tensor):
    """The batch of samples ``index``: a signal each, a description, a view, the input noise."""
    size = len(index)
    signal = draw_signals(size, run.gen, cfg, None if run.labelled is None else run.labelled[index])
    alternative = torch.randint(8, (size,), generator=run.gen)
    opposite = torch.rand(size, generator=run.gen) < cfg.opposite_prob
    opposite &= signal != EXECUTE  # execute shows no action to the encoder
    batch = make_batch(run.data, index, signal, alternative, opposite)
    if cfg.input_noise or cfg.joint_input_noise:  # regularises what the action encoder reads (model units)
        batch.action_input = add_input_noise(batch.action_input, cfg.input_noise, cfg.joint_input_noise)
    return batch


def _step(run: Run, cfg, batch, index: torch.Tensor, language: torch.Tensor | None, weights: torch.Tensor,
          device: torch.device) -> tuple[dict, torch.Tensor]:
    """One optimiser step on a batch: its outputs and its (total, language, action) loss."""
    out = run.model(batch, teacher_language=cfg.teacher_language,
                    feedback="greedy" if cfg.teacher_language else "soft", language=language)
    loss, lang, act = pgae_loss(out, batch, weights, cfg.language_weight, cfg.action_weight)
    if run.plans is not None:      # Deviation from paper: L += β γ L_plan (model/plan.py)
        planned = plan_loss(out["plan"], run.plans[index.to(device)], batch.signal)
        loss = loss + cfg.action_weight * cfg.plan_weight * planned
    run.optimiser.zero_grad(set_to_none=True)
    loss.backward()
    if cfg.clip:
        nn.utils.clip_grad_norm_(run.model.parameters(), cfg.clip)
    run.optimiser.step()
    return out, torch.tensor([loss.item(), lang.item(), act.item()])


def _stop(losses: torch.Tensor, epoch: int, batch: int, batches: int,
          signal: torch.Tensor) -> None:
    """Raise :class:`NonFiniteLossError` for a batch whose loss is NaN or infinite."""
    total, lang, act = losses.tolist()
    signals = ", ".join(SIGNALS[i] for i in sorted(set(signal.tolist())))
    raise NonFiniteLossError(
        f"training stopped: the loss is {total} (language {lang}, action {act}) at "
        f"epoch {epoch + 1}, batch {batch + 1} of {batches} (signals {signals}); look "
        "for extreme values in the data, or lower the learning rate")


__all__ = ["NonFiniteLossError", "Run", "Trained", "batch_indices", "train"]
