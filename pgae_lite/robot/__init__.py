"""The trained model drives the simulated robot (chapters 07 and 08).

- ``closedloop``         open and closed loop on the test episodes (chapter 07)
- ``instructions``       free-form instructions, executed both ways (chapter 07)
- ``typed_text``         a text typed for a model, read once: its words, or free text and its features
- ``playground``         one signal on one episode, and its ipywidgets front end (chapter 08)
- ``play_result``        what one call of the playground produced, and how it is shown
- ``playground_checks``  the playground's argument checks
"""
