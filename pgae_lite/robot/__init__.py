"""The trained model drives the simulated robot (chapters 07 and 08).

- ``closedloop``         open and closed loop on the test episodes (chapter 07)
- ``instructions``       free-form instructions, executed both ways (chapter 07)
- ``playground``         one signal on one episode, and its ipywidgets front end (chapter 08)
- ``playground_checks``  the playground's argument checks
"""
