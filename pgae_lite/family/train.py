"""Training PRAE and PVAE: both autoencoders at once, bound by the binding loss.

PGAE paper, Sec. 2 (PRAE, PVAE) and Sec. 4 ("Training Details", for the shared parts). Each
step takes a batch of paired samples, and each autoencoder rebuilds its own modality::

    L = CE(words) + MSE(joints) + w_bind * L_bind(z_L, z_A)           PRAE (w_bind = 1)
      + KL(mu_L, s_L) + KL(mu_A, s_A)                                   PVAE (w_bind = 2, on the means)

PRAE reads one description per action (the first of the 8: its paper's one-to-one data); PVAE
(and PVAE-BERT, PVAE with the pretrained encoder) draws one of the 8 equivalent descriptions for
each sample at each step, as its authors do.
The words' weights and the joints' MSE are PGAE's (:func:`pgae_lite.train.loss.pgae_loss`), and
so are the optimiser, its schedule and the input noise of the ``book`` recipe (``recipe``), but not its
batches of one length (:func:`pgae_lite.train.loop.batch_indices`): the binding loss compares the codes
within a batch, and a batch of one length never holds a slow and a fast action together. With them,
PVAE described about half of the authors' test actions, not all (seed 0, ``results/family_length_batches.json``).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, replace

import torch

from pgae_lite.data.dataset import Normaliser, PGAEDataset
from pgae_lite.bert.tuned_encoder import TUNED_SHARE
from pgae_lite.family.binding import binding_loss
from pgae_lite.family.prae import PRAE, paired_inputs
from pgae_lite.family.pvae import BINDING_WEIGHT, KL_WEIGHT, PVAE, kl_divergence
from pgae_lite.model.config import ModelConfig
from pgae_lite.model.signals import make_batch, signal_ids
from pgae_lite.train.checkpoint import training_split
from pgae_lite.train.config import TrainConfig
from pgae_lite.train.loss import add_input_noise, lr_factor, parameter_groups, pgae_loss
from pgae_lite.util.storage import default_device, training_threads
from pgae_lite.world.words import word_weights

#: name -> (the model, what it changes in the ModelConfig). PVAE-BERT: PVAE reading descriptions through the
#: pretrained encoder this package ships, frozen; PVAE-BERT-tuned: the same with the encoder's top layer tuned
#: (bert/tuned_encoder.py). Deviation from paper: PVAE-BERT fine-tunes the whole of BERT-base.
MODELS = {"PRAE": (PRAE, {}), "PVAE": (PVAE, {}), "PVAE-BERT": (PVAE, {"language_encoder": "pretrained"}),
          "PVAE-BERT-tuned": (PVAE, {"language_encoder": "pretrained", "tuned_top_layer": True})}
#: The authors' training of each (iterations, batch, Adam's rate), the ``paper`` profile's: PRAE's code 20,000
#: iterations of 50 at 1e-3; PVAE's 15,000 of 100 at 1e-4; PVAE-BERT's (either encoder) 40,000 of 100 at 1e-4.
AUTHORS_TRAINING = {"PRAE": (20_000, 50, 1e-3), "PVAE": (15_000, 100, 1e-4), "PVAE-BERT": (40_000, 100, 1e-4),
                    "PVAE-BERT-tuned": (40_000, 100, 1e-4)}
#: Which training code made a saved model (saved beside it, runs/configured_unit.py): 2 = PGAE's fused
#: optimiser and parameter groups, a tuned top layer learning in its first share of steps; 1 = before.
TRAINING_VERSION = 2


def family_recipe(name: str, recipe: TrainConfig, profile_name: str, samples: int) -> TrainConfig:
    """The recipe ``name`` trains with: ``recipe`` (the profile's), or under the ``paper`` profile its authors'
    iterations, batch and rate, as epochs of the ``samples`` training samples (at least one)."""
    if profile_name != "paper":
        return recipe
    iterations, batch, lr = AUTHORS_TRAINING[name]
    return replace(recipe, epochs=max(1, round(iterations * batch / samples)), batch_size=batch, lr=lr)


@dataclass
class FamilyTrained:
    """A trained PRAE or PVAE, the normaliser of its data, its loss per epoch and its training time (s)."""

    model: PRAE
    normaliser: Normaliser
    history: list[dict]
    seconds: float


def family_loss(model: PRAE, batch, weights: torch.Tensor) -> tuple[torch.Tensor, dict]:
    """The loss of one batch (see the module) and its terms."""
    out = model(**paired_inputs(batch), steps=batch.joint_mask.sum(1))
    _, words, joints = pgae_loss({"logits": out[0], "joints": out[1]}, batch, weights)
    if isinstance(model, PVAE):
        mean_l, mean_a, log_var_l, log_var_a = out[2:]
        bind = binding_loss(mean_l, mean_a)                                   # on the means
        kl = kl_divergence(mean_l, log_var_l) + kl_divergence(mean_a, log_var_a)
        total = words + joints + BINDING_WEIGHT * bind + KL_WEIGHT * kl
    else:
        bind, kl = binding_loss(out[2], out[3]), torch.zeros(())
        total = words + joints + bind
    return total, {"words": words.item(), "joints": joints.item(), "binding": bind.item(), "kl": kl.item()}


def train_family(name: str, dataset: PGAEDataset, model_cfg: ModelConfig | None = None,
                 recipe: TrainConfig | None = None, device: str | None = None,
                 all_descriptions: bool | None = None) -> FamilyTrained:
    """Train ``name`` (a key of :data:`MODELS`) on the training split of ``dataset``.

    ``all_descriptions``: whether each step draws one of the 8 descriptions (True) or reads the first
    (False); None: the model's own (PRAE the first, PVAE all 8). PRAE with True is the one-to-many
    experiment: a deterministic code for 8 descriptions of one action.
    """
    if name not in MODELS:
        raise ValueError(f"unknown family model {name!r}; the options are: {', '.join(MODELS)}")
    recipe, device = recipe or TrainConfig(), torch.device(device or default_device())
    train_set = training_split(dataset, recipe.max_train_samples)      # the training split (or its first samples)
    normaliser = Normaliser.fit(train_set, recipe.vision_scaling)
    with training_threads(device):
        torch.manual_seed(recipe.seed)
        make, changes = MODELS[name]
        draw = make is PVAE if all_descriptions is None else all_descriptions
        model = make(replace(model_cfg or ModelConfig(), **changes)).to(device)
        data = normaliser.tensors(train_set, device)
        weights = word_weights().to(device)
        gen = torch.Generator().manual_seed(recipe.seed)
        fused = dict(fused=True) if device.type in ("cpu", "cuda") else {}   # one kernel, as PGAE's loop
        optimiser = torch.optim.AdamW(parameter_groups(model), lr=recipe.lr, weight_decay=recipe.weight_decay,
                                      **fused)
        n, history, step, t0 = len(train_set), [], 0, time.perf_counter()
        steps = recipe.epochs * -(-n // recipe.batch_size)
        stop_tuning = round(TUNED_SHARE * steps) if hasattr(model.language_encoder, "stop_learning") else None
        for _ in range(recipe.epochs):
            model.train()
            terms = []
            for index in torch.randperm(n, generator=gen).split(recipe.batch_size):      # batches of any samples
                if step == stop_tuning:                     # a tuned top layer: its share of the steps is over
                    model.language_encoder.stop_learning()
                alternative = (torch.randint(0, 8, (len(index),), generator=gen) if draw
                               else torch.zeros(len(index), dtype=torch.long))      # PRAE: one description
                batch = make_batch(data, index, signal_ids("repeat both", len(index)), alternative)
                batch.action_input = add_input_noise(batch.action_input, recipe.input_noise,
                                                     recipe.joint_input_noise)
                for group in optimiser.param_groups:         # warm-up, cosine decay; a tuned top layer's lr_scale
                    group["lr"] = recipe.lr * lr_factor(step, steps, recipe.warmup, recipe.schedule) * group["lr_scale"]
                loss, parts = family_loss(model, batch, weights)
                optimiser.zero_grad()
                loss.backward()
                if recipe.clip:
                    torch.nn.utils.clip_grad_norm_(model.parameters(), recipe.clip)
                optimiser.step()
                terms.append(parts)
                step += 1
            history.append({k: sum(t[k] for t in terms) / len(terms) for k in terms[0]})
        model.eval()
    return FamilyTrained(model, normaliser, history, time.perf_counter() - t0)


__all__ = ["AUTHORS_TRAINING", "TRAINING_VERSION", "FamilyTrained", "MODELS", "family_loss", "family_recipe",
           "train_family"]
