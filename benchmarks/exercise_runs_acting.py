"""The runs of the solutions of the exercises of chapters 06, 07 and appendices A3, A4 (not in the paper).

Part of ``benchmarks/exercise_runs.py``, which merges :data:`EXERCISES` into its own and writes every
entry into results/exercise_runs.json. Each function runs what the solution of one exercise runs,
through the same calls of the package, in the profile given, and returns its figures:

    ex-opp-mirror     chapter 06: PGAE-views trained with the opposite agent's push described as "pull"
    ex-opp-prob       chapter 06: PGAE trained with 0, 1/4, 1/2 (PGAE-views) and 3/4 of opposite-view samples
    ex-colour-cae     appendix A3: the CAE of the world with an orange cube, against the paper's world's
    ex-loop-measured  chapter 07: the paper's decoder (its own predictions fed back) in the closed loop, and
                      the same loop fed the measured joints
    ex-bert-finetune  appendix A4: PGAE-BERT with the transformer's last layer fine-tuned, at the recipe's rate
                      and at a hundredth of it, against the frozen one
"""
from __future__ import annotations

import copy
import time
from dataclasses import replace

import numpy as np
import torch

import pgae_lite.model.loss as loss_module
from pgae_lite.bert.pretrained import input_text, load_transformer, tokens_to_text
from pgae_lite.cae import extract_features
from pgae_lite.config import get_profile, with_world
from pgae_lite.evaluate.table1 import evaluate, predict
from pgae_lite.freeform.paraphrases import load_paraphrases
from pgae_lite.model.build import build_model
from pgae_lite.model.language import LanguageEncoderBase
from pgae_lite.model.signals import DESCRIBE, make_batch
from pgae_lite.robot.closedloop import POSITION_GAIN, compare, execute_batch
from pgae_lite.runs.data import cae_path, trained_cae, worker_dataset
from pgae_lite.runs.pipeline import trained_model
from pgae_lite.runs.rows import TRAININGS
from pgae_lite.sim import HOME_POSE, Scene, SceneLayout, Simulation
from pgae_lite.sim.dataset import generate
from pgae_lite.train.loop import train
from pgae_lite.util.storage import load_torch
from pgae_lite.world.colours import with_colour
from pgae_lite.world.patterns import Pattern
from pgae_lite.world.words import CANONICAL, VOCABULARY, WORD_INDEX, equivalent_descriptions, is_correct

MIRROR = {"push": "pull", "pull": "push", "move-up": "move-down", "move-down": "move-up"}   # ex-opp-mirror
SHARES = (0.0, 0.25, 0.5, 0.75)                    # ex-opp-prob: 0 is the plain PGAE, 0.5 the chapter's PGAE-views
ORANGE = ("orange", "amber", (0.98, 0.50, 0.05, 1.0))   # appendix A3's colour: name, synonym, RGBA
FINETUNE_LR_SCALE = 0.01     # ex-bert-finetune's second try: the recipe's 3e-3 -> 3e-5, in the usual fine-tuning range


def cells(trained, data, **options) -> dict:
    """Table 1's cells of a trained model, rounded."""
    found, _ = evaluate(trained.model, data, trained.normaliser, **options)
    return {s: {k: None if v is None else round(v, 4) for k, v in c.items()} for s, c in found.items()}


def the_views(profile, seed: int):
    """Chapter 06's PGAE-views (cached)."""
    return trained_model(TRAININGS["PGAE-views"], get_profile(profile), seed, progress=False)


# --------------------------------------------------------------------------- chapter 06
def opp_mirror(profile, seeds, **_):
    data, runs = worker_dataset(None, profile, "cpu"), []
    test_set = data.split("test")
    swap = torch.arange(len(VOCABULARY))                         # word index -> word index
    for a, b in MIRROR.items():
        swap[WORD_INDEX[a]] = WORD_INDEX[b]

    def mirrored_batch(tensors, index, signal, alternative, opposite=None):
        batch = make_batch(tensors, index, signal, alternative, opposite)
        if opposite is not None:                                 # the other agent's push is called "pull"
            flip = (opposite.to(batch.signal.device) & (batch.signal == DESCRIBE))[:, None]
            batch.lang_target = torch.where(flip, swap.to(flip.device)[batch.lang_target], batch.lang_target)
        return batch

    def nico_words(i):                                           # the 8 descriptions in NICO's frame
        action, colour, speed = (CANONICAL[VOCABULARY[w]] for w in test_set.descriptions[i, 0])
        return equivalent_descriptions(MIRROR.get(action, action), colour, speed)

    for seed in seeds:
        views = the_views(profile, seed)
        loss_module.make_batch = mirrored_batch                  # PGAE's training_batch calls it
        try:
            mirrored = train(data, views.profile, progress=False)
        finally:
            loss_module.make_batch = make_batch
        m_self, _ = evaluate(mirrored.model, data, mirrored.normaliser)
        m_opp, m_preds = evaluate(mirrored.model, data, mirrored.normaliser, opposite=True)
        nico = 100 * np.mean([is_correct(t, nico_words(i)) for i, t in enumerate(m_preds["describe"].text)])
        chapters = {view: cells(views, data, opposite=opposite)["describe"]["accuracy"]
                    for view, opposite in (("nico", False), ("opposite", True))}
        runs.append({"seed": seed, "train_seconds": round(mirrored.seconds, 1),
                     "views": {"train_seconds": round(views.seconds, 1), "describe_nico_view": chapters["nico"],
                               "describe_opposite_view": chapters["opposite"]},
                     "mirrored": {"describe_nico_view": round(m_self["describe"]["accuracy"], 4),
                                  "describe_opposite_view_actors_words": round(m_opp["describe"]["accuracy"], 4),
                                  "describe_opposite_view_nicos_words": round(float(nico), 4)},
                     "n": m_self["describe"]["n"]})
    return {"runs": runs}


def opp_prob(profile, seeds, **_):
    data, runs = worker_dataset(None, profile, "cpu"), []
    for seed in seeds:
        for p in SHARES:
            t = the_views(profile, seed) if p == 0.5 else trained_model(
                TRAININGS["PGAE"], get_profile(profile, opposite_prob=p), seed, progress=False)
            views = {}
            for view, opposite in (("nico", False), ("opposite", True)):
                c = cells(t, data, opposite=opposite)
                views[view] = {"describe": c["describe"]["accuracy"],
                               "repeat_action_nrmse": c["repeat action"]["nrmse"]}
            runs.append({"seed": seed, "opposite_prob": p, "train_seconds": round(t.seconds, 1), **views})
    return {"runs": runs}


# --------------------------------------------------------------------------- appendix A3
def colour_cae(profile, seeds, **_):
    world = with_colour(ORANGE[0], synonym=ORANGE[1], rgba=ORANGE[2])
    coloured = with_world(get_profile(profile), world)          # the profile in the new world
    t0 = time.perf_counter()
    generate(coloured.data, progress=False)                     # the new world's recordings (cached)
    recorded = round(time.perf_counter() - t0, 1)
    new_cae, _ = trained_cae(coloured, progress=False)          # on old and new training frames (cached)
    old_cae, _ = trained_cae(profile, progress=False)
    views = []
    for colour in ("red", "orange", "yellow"):                  # pattern 144's scene, the left cube recoloured
        scene = Scene(SceneLayout(colour, "blue", palette=world.rgba))
        views.append(scene.render())
        scene.close()
    sums = {}
    for name, cae, prof in (("old", old_cae, profile), ("new", new_cae, coloured)):
        red, orange, yellow = extract_features(cae, np.stack(views))      # (30,) each
        sums[name] = {"orange_red": round(float(np.abs(orange - red).sum()), 4),
                      "orange_yellow": round(float(np.abs(orange - yellow).sum()), 4),
                      "red_yellow": round(float(np.abs(red - yellow).sum()), 4),     # the scale of the two
                      "train_seconds": round(load_torch(cae_path(prof.data, prof.cae), ("seconds",))["seconds"], 1)}
    return {"record_seconds": recorded, "cae": sums, "runs": [{"seed": profile.cae.seed, **sums["new"]}]}


# --------------------------------------------------------------------------- chapter 07
def loop_measured(profile, seeds, **_):
    data, runs = worker_dataset(None, profile, "cpu"), []
    config, episodes = profile.data, profile.chapters.test_episodes
    cae, _ = trained_cae(profile, progress=False)
    alpha = 1 - (1 - POSITION_GAIN) ** config.sim.substeps     # share of the gap the motors close in one step
    sim = Simulation(config.sim)

    def rate(passed) -> float:
        return round(100 * float(np.mean(passed)), 2)

    for seed in seeds:
        pgae = trained_model(TRAININGS["PGAE"], profile, seed, progress=False)     # the book's decoder (cached)
        table = compare(pgae.model, cae, pgae.normaliser, data, limit=episodes, config=config, progress=False)
        book = get_profile(profile, seed=seed)
        own = train(data, replace(book, model=replace(book.model, joint_feedback="predicted", time_stride=1)),
                    progress=False)
        model, normaliser = own.model, own.normaliser
        device = next(model.parameters()).device

        def see(frame):                                          # camera frame -> v_t (1, 30), model units
            return torch.from_numpy(normaliser.vision_to_model(extract_features(cae, frame[None]))).to(device)

        def measured_joints():
            return torch.from_numpy(normaliser.joints_to_model(sim.joints()))[None].to(device)   # (1, 5)

        @torch.no_grad()
        def closed_loop_measured(pattern, variation, words):    # the solution's loop: the measured joints fed back
            sim.reset(pattern, variation, config.base_seed, render=False)
            v, j = see(sim.step(np.array(HOME_POSE))), measured_joints()
            h, _ = model.encode(execute_batch(v[0], j[0], words, device))
            state, start = model.action_decoder.begin(h), j
            for _ in range(1, Pattern.from_number(pattern).steps):
                wanted, state = model.action_decoder.step(state, v, j, start)
                q = sim.joints()
                v = see(sim.step(q + (normaliser.joints_to_data(wanted)[0].cpu().numpy() - q) / alpha))
                j = measured_joints()                            # what the arm did
            return sim.check().passed

        predicted = compare(model, cae, normaliser, data, limit=episodes, config=config, progress=False)
        measured = [closed_loop_measured(int(r.pattern), int(r.variation), tuple(r.description.split()))
                    for r in table.itertuples()]
        runs.append({"seed": seed, "train_seconds": round(own.seconds, 1), "episodes": len(table),
                     "book_decoder": {"open_%": rate(table["open_passed"]), "closed_%": rate(table["closed_passed"])},
                     "paper_decoder": {"open_%": rate(predicted["open_passed"]),
                                       "closed_%": rate(predicted["closed_passed"]), "measured_%": rate(measured),
                                       "execute_nrmse": cells(own, data)["execute"]["nrmse"]},
                     "failed": {"book_decoder": list(table.loc[~table["closed_passed"], "id"]),
                                "paper_decoder": list(predicted.loc[~predicted["closed_passed"], "id"]),
                                "measured": [i for i, ok in zip(table["id"], measured) if not ok]}})
    return {"runs": runs}


# --------------------------------------------------------------------------- appendix A4
class FineTunedEncoder(LanguageEncoderBase):
    """The solution's encoder: the transformer inside the model, its last ``trainable`` layers trained; mean
    pooling. (LanguageEncoderBase: the interface the training loop and the robot call.)"""

    reads_free_text = True

    def __init__(self, name=None, trainable=1):
        super().__init__()
        loaded = load_transformer(name)
        self.tokenizer = loaded.tokenizer
        self.transformer = copy.deepcopy(loaded.model)          # our own copy: the shared one stays frozen
        for layer in self.transformer.encoder.layer[-trainable:]:
            layer.requires_grad_(True)
        self.output_dim = self.transformer.config.hidden_size

    def encode_texts(self, texts):
        device = next(self.transformer.parameters()).device
        batch = self.tokenizer(list(texts), padding=True, return_tensors="pt").to(device)
        hidden = self.transformer(**batch).last_hidden_state                 # (B, tokens, D)
        m = batch["attention_mask"][..., None].float()                       # (B, tokens, 1)
        return (hidden * m).sum(1) / m.sum(1)

    def forward(self, tokens, lengths=None):
        return self.encode_texts([tokens_to_text(row) for row in tokens.cpu()])


def readback(trained, test_set) -> dict:
    """Appendix A4's section 4: the 108 held-out paraphrases said back (``repeat language``), each on the
    first test episode of its meaning; the share said back right."""
    paraphrases = load_paraphrases()
    meaning_of = [tuple(VOCABULARY[w] for w in d[0]) for d in test_set.descriptions]
    ks = [q for q, p in enumerate(paraphrases) if p.meaning in meaning_of]
    told = [input_text("repeat language", paraphrases[q].text) for q in ks]
    with torch.no_grad():
        heard = trained.model.language_encoder.encode_texts(told)           # (108, D)
    back = predict(trained.model, test_set.subset([meaning_of.index(paraphrases[q].meaning) for q in ks]),
                   trained.normaliser, "repeat language", language=heard).text
    right = [is_correct(t, equivalent_descriptions(*paraphrases[q].meaning)) for q, t in zip(ks, back)]
    return {"paraphrases": len(ks), "right": int(sum(right)), "readback_%": round(100 * float(np.mean(right)), 2)}


def bert_finetune(profile, seeds, **_):
    """ex-bert-finetune: the solution's encoder trained with the recipe, at the recipe's rate and, as the
    solution advises where that goes badly, at a small one (``lr_scale``: a group of its own, no weight decay)."""
    data, runs = worker_dataset(None, profile, "cpu"), []
    test_set = data.split("test")
    for seed in seeds:
        recipe = TRAININGS["PGAE-BERT"].profile(get_profile(profile, seed=seed))
        frozen = trained_model(TRAININGS["PGAE-BERT"], get_profile(profile), seed, progress=False)   # cached
        run = {"seed": seed, "epochs": recipe.train.epochs,
               "frozen": {"train_seconds": round(frozen.seconds, 1), "table1": cells(frozen, data),
                          "readback": readback(frozen, test_set)}}
        for name, lr_scale in (("tuned", None), ("tuned_small_rate", FINETUNE_LR_SCALE)):
            torch.manual_seed(seed)
            model = build_model(recipe.model)
            model.language_encoder = FineTunedEncoder(trainable=1)
            if lr_scale is not None:
                model.language_encoder.lr_scale = lr_scale     # pgae_lite.train.optimiser.parameter_groups
            tuned = train(data, recipe, model=model, progress=False)
            run["trainable_parameters"] = sum(p.numel() for p in model.language_encoder.parameters()
                                              if p.requires_grad)
            run[name] = {"lr": recipe.train.lr * (lr_scale or 1.0), "train_seconds": round(tuned.seconds, 1),
                         "table1": cells(tuned, data), "readback": readback(tuned, test_set)}
        runs.append(run)
    return {"runs": runs}


#: label -> (the exercise's run, its seeds by default): one seed, every training here takes over 3 minutes
EXERCISES = {
    "ex-opp-mirror": (opp_mirror, (0,)), "ex-opp-prob": (opp_prob, (0,)), "ex-colour-cae": (colour_cae, (0,)),
    "ex-loop-measured": (loop_measured, (0,)), "ex-bert-finetune": (bert_finetune, (0,)),
}


if __name__ == "__main__":     # run as a script: the one entry point, benchmarks/exercise_runs.py, with these arguments
    import runpy
    import sys
    from pathlib import Path

    sys.argv[0] = str(Path(__file__).with_name("exercise_runs.py"))
    runpy.run_path(sys.argv[0], run_name="__main__")
