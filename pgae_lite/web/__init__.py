"""The book in the reader's browser: the trained models as ONNX graphs (not in the paper).

- ``export``    one episode's forward pass as an ONNX graph, and its parity with PyTorch
- ``sentence``  PGAE-BERT's sentence encoder for free text: the transformer and each model's head
- ``assets``    what the live playground reads in the page: models, feature tables, test episodes
"""
