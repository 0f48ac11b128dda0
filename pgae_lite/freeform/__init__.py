"""Free-form language: reading instructions said in any words, and refusing what the robot cannot do (appendix A4).

Not in the paper, which says PGAE-BERT "has the potential to recognise unseen natural language".

- ``phrase_lexicon``     the words and phrases the generated sentences use, and those held out
- ``phrasings``          generated ways of saying each instruction
- ``word_lookup``        words never trained on, looked up in WordNet
- ``attention_pooling``  the free-form variant's encoder: attention over the transformer's tokens; ``AttentionConfig``
- ``phrasing_bank``      training on phrasings: the bank of their sentence vectors; ``PhrasingsConfig``
- ``paraphrases``        held-out free-form paraphrases of the test instructions
- ``refusal_words``      the refusal rule's closed classes of English: polite negations, quantifiers, repetitions
- ``refusals``           what the robot will not do with a free instruction, and says instead
- ``refusal_cases``      the refusal rule's test cases: for the unit tests, and the page's parity check
- ``refusal_grammar``    a grammar of instructions to refuse and to act on: the refusal benchmark's, and the page's
- ``refusal_typed_grammar``  typed variants in two template sets (development, held-out): the refusal benchmark's
"""
