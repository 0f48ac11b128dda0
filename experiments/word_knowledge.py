"""Word knowledge: does the frozen transformer place a held-out word nearest its own meaning?

    python experiments/word_knowledge.py [--model NAME_OR_FOLDER]

No PGAE, no training. Each one-word phrase of the lexicon is put into one
carrier sentence per slot (``{} the red cube slowly`` for an action,
``push the {} cube slowly`` for a colour, ``push the red cube {}`` for a speed)
and read as the mean of its token vectors there. A word of
:func:`pgae_lite.freeform.phrase_lexicon.held_out_words` is given the meaning of the
training word (of ``PGAE-BERT-phrasings-held-out``'s lexicon) whose vector is
closest by cosine. A held-out word that lands nearest another meaning is one the
encoder does not place with its meaning, so a read-out trained on the other words
has little to go on for it: a guide to the unseen-word measure of
``benchmarks/free_language.py``, not a bound (a trained read-out also uses the
rest of the sentence). The test paraphrases are never read.
"""
import argparse

import torch

from pgae_lite.bert.pretrained import load_transformer
from pgae_lite.freeform.phrase_lexicon import LEXICON, SLOTS, held_out_words, training_lexicon, words_of

CARRIERS = {"action": "{} the red cube slowly", "colour": "push the {} cube slowly",
            "speed": "push the red cube {}"}

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--model", default=None, help="a Hugging Face name or folder (default: all-MiniLM-L6-v2)")
args = parser.parse_args()
torch.set_num_threads(1)
tf = load_transformer(args.model)


@torch.no_grad()
def word_vector(slot: str, word: str) -> torch.Tensor:
    """The mean of ``word``'s token vectors inside its slot's carrier sentence, unit length (D,)."""
    before = CARRIERS[slot].split("{}")[0]
    start = 1 + len(tf.tokenizer(before, add_special_tokens=False)["input_ids"])   # after [CLS]
    count = len(tf.tokenizer(word, add_special_tokens=False)["input_ids"])
    hidden = tf.model(**tf.tokenizer([CARRIERS[slot].format(word)], return_tensors="pt")).last_hidden_state[0]
    return torch.nn.functional.normalize(hidden[start:start + count].mean(0), dim=0)


held = set(held_out_words())
trained_on = training_lexicon("held-out")
for slot in SLOTS:
    known = {m: torch.stack([word_vector(slot, p) for p in phrases if len(words_of(p)) == 1])
             for m, phrases in trained_on.phrases(slot).items()}
    right = total = 0
    for meaning, phrases in LEXICON.phrases(slot).items():
        for word in (p for p in phrases if p in held):
            v = word_vector(slot, word)
            nearest = {m: float((vectors @ v).max()) for m, vectors in known.items()}
            guess = max(nearest, key=nearest.get)
            right, total = right + (guess == meaning), total + 1
            print(f"{slot:7s} {word:12s} is {meaning:8s} nearest {guess:8s} "
                  + " ".join(f"{m} {c:.2f}" for m, c in nearest.items()))
    print(f"{slot}: {right} of {total} held-out words nearest their own meaning\n")
