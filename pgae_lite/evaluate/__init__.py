"""Measuring models: the paper's Table 1, and how they answer incongruent input (paper Sec. 4; PTAE).

- ``table1``       Table 1's measures: description accuracy and joint nRMSE, N.A. where a model has no path
- ``incongruent``  the family's experiment: which modality a model follows when action and words disagree
"""
