"""The training loop of every model, as a short sequence of named steps (paper Sec. 3, "Loss Function"; Sec. 4).

    setup -> resume -> for each epoch, for each batch: the model's batch -> language features
          -> the model's loss -> step -> record the epoch -> checkpoint

One loop trains PGAE, PGAE-BERT, PTAE, PRAE, PVAE and the book's variants: the model says what it
learns from (``training_data``, ``training_batch``: which draws its batches take; ``training_loss``:
its loss and the terms to record; ``at_step``; :mod:`pgae_lite.model.loss`, :mod:`pgae_lite.model.prae`),
the loop does the rest. Training is deterministic under a seed (bit for bit on the same kind of
device: on the CPU it runs on a fixed number of torch threads,
:func:`~pgae_lite.util.storage.training_threads`, since a 1-thread and a 2-thread run round sums
differently and drift apart), runs on CUDA when present (else the CPU), and resumes from its last
checkpoint after an interruption (:mod:`pgae_lite.train.checkpoint`). What a training needs beyond
its recipe the caller hands in: a model built otherwise (a larger lexicon), or ``language``, the
source of each batch's language features (the free-form variant's phrasings,
:func:`pgae_lite.freeform.phrasing_bank.for_training`).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import torch
from torch import nn
from tqdm.auto import tqdm

from pgae_lite.data.dataset import PGAEDataset
from pgae_lite.data.normaliser import Normaliser
from pgae_lite.model.build import build_model
from pgae_lite.train.checkpoint import (
    CHECKPOINT,
    check_recipe_version,
    check_trained_on,
    load_checkpoint,
    load_weights,
    save_checkpoint,
    training_split,
)
from pgae_lite.train.draws import Draws
from pgae_lite.train.optimiser import lr_factor, parameter_groups
from pgae_lite.train.supervision import labelled_samples
from pgae_lite.util.errors import ArgumentError, PGAELiteError
from pgae_lite.util.storage import (
    CheckpointMismatchError,
    OutputError,
    default_device,
    folder_lock,
    training_threads,
)
from pgae_lite.world.words import SIGNALS


class NonFiniteLossError(PGAELiteError, FloatingPointError):
    """The training loss became NaN or infinite: the run stops, nothing is saved."""


@dataclass
class Trained:
    """What :func:`train` returns: the model, its normaliser, the history and the wall time."""

    model: nn.Module
    normaliser: Normaliser
    history: list[dict]
    profile: object          # the pgae_lite.config.Profile it was trained with
    seconds: float


@dataclass
class Run:
    """What a training carries from step to step."""

    model: nn.Module
    optimiser: torch.optim.Optimizer
    gen: torch.Generator                 # shuffling, and the draws: signals, descriptions, views
    draws: Draws                         # what a batch draws, from the recipe and gen
    data: dict[str, torch.Tensor]        # the training samples, normalised, on the device (and what the loss reads)
    lengths: torch.Tensor                # each sample's length, on the CPU (for the batches)
    batches: int                         # per epoch
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
          model: nn.Module | None = None, callback=None, name: str = "PGAE", language=None) -> Trained:
    """Train the model of ``profile``'s recipe on the training split of ``dataset``.

    ``profile``: a :class:`~pgae_lite.config.Profile` (``pgae_lite.config.get_profile(name)``); its
    ``model`` settings say which model (:func:`~pgae_lite.model.build.build_model`), unless ``model``
    is given (built by the caller, e.g. for a larger lexicon, under ``torch.manual_seed(recipe seed)``).
    ``language(model)``, if given, makes the source of each batch's language features: an object whose
    ``features(model, batch, generator, step)`` gives them (the free-form variant's phrasings).
    With ``out_dir`` a checkpoint is written there every
    ``checkpoint_every`` epochs and at the end (atomically); a later call with
    the same ``out_dir`` and profile resumes from it, and one whose training
    finished returns at once. While it runs, a lock file in ``out_dir`` makes a
    second run there fail (:class:`~pgae_lite.util.folder_lock.FolderBusyError`).
    ``callback(epoch, model, record)``, if given, is called after every epoch
    (e.g. to evaluate along the way). A NaN or infinite loss stops the run
    (:class:`NonFiniteLossError`, naming the epoch and the batch). ``name``: the model's, on the progress
    bar, which shows only while there are epochs to train (a finished model loaded from ``out_dir`` shows none).
    """
    if not hasattr(profile, "to_dict") or not hasattr(profile, "train"):
        raise TypeError(f"train takes a Profile, e.g. pgae_lite.config.get_profile('book'); got {profile!r}")
    device = torch.device(device) if device else default_device()
    args = (dataset, profile, out_dir, device, progress, model, callback, name, language)
    with training_threads(device):   # on the CPU a fixed thread count: the same model on any machine
        if out_dir is None:
            return _train(*args)
        with folder_lock(out_dir) as writable:      # not writable (a read-only cache): a finished model is read
            return _train(*args, writable=writable)


def _train(dataset: PGAEDataset, profile, out_dir: str | Path | None, device: torch.device,
           progress: bool, model: nn.Module | None, callback, name: str, language,
           writable: bool = True) -> Trained:
    cfg = profile.train
    cfg.__post_init__()              # checked again: a field may have been set since
    if cfg.phrasings is not None and language is None:
        raise ArgumentError("this recipe trains on phrasings (TrainConfig.phrasings), which the loop does not make "
                            "itself: hand it their source, train(..., language=pgae_lite.runs.pipeline."
                            "language_source(profile)), or train through pgae_lite.runs.pipeline.trained_model")
    train_set = training_split(dataset, cfg.max_train_samples)
    normaliser = Normaliser.fit(train_set, cfg.vision_scaling)
    run = _setup(train_set, normaliser, profile, device, model)
    ckpt_path = Path(out_dir) / CHECKPOINT if out_dir else None
    if ckpt_path and ckpt_path.exists():
        _resume(run, ckpt_path, profile, normaliser, dataset.source)
    if not writable and run.epoch < cfg.epochs:
        raise OutputError(f"cannot train {name} in {out_dir}: the folder cannot be written (a read-only disk, or "
                          f"no permission), and the model there is not finished ({run.epoch} of the recipe's "
                          f"{cfg.epochs} epochs trained); train it where it can be written (PGAE_LITE_CACHE)")
    t0 = time.perf_counter() - run.elapsed
    source = None if language is None else language(run.model)    # its encoding time counts as training time
    bar = tqdm(range(run.epoch, cfg.epochs), desc=f"{name} ({profile.name})", initial=run.epoch, total=cfg.epochs,
               disable=not progress or run.epoch >= cfg.epochs)          # nothing to train: no bar
    for epoch in bar:
        record = _epoch(run, cfg, epoch, source)
        bar.set_postfix_str(", ".join(f"{k} {v:.4g}" for k, v in record.items() if isinstance(v, float) and k != "lr"))
        if callback is not None:
            callback(epoch + 1, run.model, record)
            run.model.train()
        if ckpt_path and (epoch + 1 == cfg.epochs or (epoch + 1) % cfg.checkpoint_every == 0):
            save_checkpoint(ckpt_path, run.model, run.optimiser, run.gen, epoch + 1, run.history, profile,
                            normaliser, time.perf_counter() - t0)
    run.model.at_step(cfg.epochs * run.batches, cfg.epochs * run.batches)     # training is over
    run.model.eval()
    return Trained(run.model, normaliser, run.history, profile, time.perf_counter() - t0)


def _setup(train_set: PGAEDataset, normaliser: Normaliser, profile, device: torch.device,
           model: nn.Module | None) -> Run:
    """The model (seeded), what its loss reads, the optimiser, the generator and the draws of a fresh run."""
    cfg = profile.train
    data = normaliser.tensors(train_set, device)
    torch.manual_seed(cfg.seed)
    model = (model or build_model(profile.model, profile.data.the_world.lexicon)).to(device)   # the world's words
    data = model.training_data(data, train_set.pattern, cfg)
    # fused: one kernel for all parameters (measured: benchmarks/profile_epoch.py, A2)
    fused = dict(fused=True) if device.type in ("cpu", "cuda") else {}
    groups = parameter_groups(model)
    optimiser = (torch.optim.AdamW(groups, lr=cfg.lr, weight_decay=cfg.weight_decay, **fused)
                 if cfg.weight_decay else torch.optim.Adam(groups, lr=cfg.lr, **fused))
    gen = torch.Generator().manual_seed(cfg.seed)
    lengths = data["lengths"].cpu()
    batches = len(batch_indices(lengths, cfg.batch_size, torch.Generator(), cfg.length_batches))
    supervision = cfg.supervision
    labelled = (labelled_samples(len(lengths), supervision.share, cfg.seed)
                if supervision is not None and supervision.of == "samples" else None)
    return Run(model, optimiser, gen, Draws(cfg, gen, labelled), data, lengths, batches)


def _resume(run: Run, path: Path, profile, normaliser: Normaliser, source: str) -> None:
    """Continue from the checkpoint at ``path``: the same recipe and data, or a clear error."""
    ckpt = load_checkpoint(path)
    check_recipe_version(ckpt["profile"], path)          # an older meaning of the options: said so
    if ckpt["profile"] != profile.to_dict():
        raise CheckpointMismatchError(
            f"{path} was trained with a different profile or seed; use another output "
            "folder, or delete the checkpoint to start again")
    check_trained_on(ckpt, normaliser.state_dict(), path, source)
    load_weights(run.model, ckpt, path)                  # the tensors it expects, each named if missing
    try:
        run.optimiser.load_state_dict(ckpt["optimiser"])
        run.gen.set_state(ckpt["generator"])
        torch.set_rng_state(ckpt["torch_rng"])
    except (ValueError, RuntimeError, TypeError, KeyError) as e:     # another optimiser's state, or altered
        first = (str(e).strip().splitlines() or [type(e).__name__])[0][:120]
        raise CheckpointMismatchError(f"{path} holds an optimiser or generator state this training cannot resume "
                                      f"from ({first}); delete the checkpoint to start again") from None
    run.epoch, run.history, run.elapsed = ckpt["epoch"], ckpt["history"], ckpt["seconds"]


def _epoch(run: Run, cfg, epoch: int, source) -> dict:
    """One epoch: every batch a step; returns (and keeps in the history) the epoch's record: the mean of each
    term of the model's loss over the samples, the rate, and a GMU's mean gate per signal."""
    run.model.train()
    epoch_batches = batch_indices(run.lengths, cfg.batch_size, run.gen, cfg.length_batches)
    total = cfg.epochs * run.batches
    sums: dict[str, float] = {}
    gate_sum, gate_n = torch.zeros(len(SIGNALS)), torch.zeros(len(SIGNALS))
    for b in range(run.batches):
        step = epoch * run.batches + b
        for g in run.optimiser.param_groups:
            g["lr"] = cfg.lr * lr_factor(step, total, cfg.warmup, cfg.schedule) * g.get("lr_scale", 1.0)
        run.model.at_step(step, total)
        index = epoch_batches[b]
        batch = run.model.training_batch(run.data, index, run.draws)
        language = None if source is None else source.features(run.model, batch, run.gen, step)
        out, terms = _step(run, cfg, batch, language)
        if not all(math.isfinite(v) for v in terms.values()):
            _stop(terms, epoch, b, run.batches, batch.signal)
        for k, v in terms.items():
            sums[k] = sums.get(k, 0.0) + v * len(index)
        if "gate" in out:                                # PGAE's GMU (PTAE, PRAE have none)
            z = out["gate"].detach().float().mean(1).cpu()   # float: also under autocast
            gate_sum.index_add_(0, batch.signal, z)
            gate_n.index_add_(0, batch.signal, torch.ones(len(index)))
    gates = (gate_sum / gate_n.clamp(min=1)).tolist()
    run.history.append({"epoch": epoch + 1, **{k: v / len(run.lengths) for k, v in sums.items()},
                        "lr": run.optimiser.param_groups[0]["lr"],
                        "gate": {s: g for s, g, k in zip(SIGNALS, gates, gate_n) if k > 0}})
    return run.history[-1]


def _step(run: Run, cfg, batch, language: torch.Tensor | None) -> tuple[dict, dict[str, float]]:
    """One optimiser step on a batch: the model's outputs, and its loss and the loss's terms as numbers."""
    loss, terms, out = run.model.training_loss(batch, cfg, language)
    run.optimiser.zero_grad(set_to_none=True)
    loss.backward()
    if cfg.clip:
        nn.utils.clip_grad_norm_(run.model.parameters(), cfg.clip)
    run.optimiser.step()
    return out, {"loss": loss.item(), **{k: v.item() for k, v in terms.items()}}


def _stop(terms: dict[str, float], epoch: int, batch: int, batches: int, signal: torch.Tensor) -> None:
    """Raise :class:`NonFiniteLossError` for a batch whose loss is NaN or infinite."""
    parts = ", ".join(f"{k} {v}" for k, v in terms.items() if k != "loss")
    signals = ", ".join(SIGNALS[i] for i in sorted(set(signal.tolist())))
    raise NonFiniteLossError(
        f"training stopped: the loss is {terms['loss']} ({parts}) at "
        f"epoch {epoch + 1}, batch {batch + 1} of {batches} (signals {signals}); look "
        "for extreme values in the data, or lower the learning rate")


__all__ = ["NonFiniteLossError", "Run", "Trained", "batch_indices", "train"]
