"""The tabletop world as data: its words, its patterns, its colours (paper Sec. 4, dataset).

- ``typed``     text as a person types it, read in one plain form (marks, spaces, fullwidth) before anything reads it
- ``words``     the paper's vocabulary, synonyms, signals, parsing (chapter 04)
- ``patterns``  the 144 patterns (speed, arrangement, action), their numbering and the test split (chapters 01, 02)
- ``colours``   the world's colours, words and patterns as one value; ``with_colour`` (appendix A3)
"""
