"""The book in the reader's browser: the trained models as ONNX graphs (not in the paper).

- ``export``        one episode's forward pass as an ONNX graph, and its parity with PyTorch
- ``sentence``      PGAE-BERT's sentence encoder for free text: the transformer and each model's head
- ``word_table``    the free-form variant's word lookup as a table the page reads
- ``refusal_data``  what the refusal rule reads (lexicon tables, WordNet's colours and verbs), for the page
- ``messages``      every message the page shows, as the templates Python formats its errors from
- ``free_text``     the files free text needs in the page: encoder, tokenizer, word tables, refusals
- ``sim_runs``      the simulator's closed-loop runs at build time, which the page shows labelled
- ``episodes``      the episodes the page offers (every test one, one per training pattern) and its form's choices
- ``parity``        Python's answers to the page's inputs, the vectors its JavaScript is tested against
- ``assets``        what the live playground reads in the page: models, feature tables, episodes, manifest
"""
