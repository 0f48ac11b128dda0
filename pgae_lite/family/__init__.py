"""The family: PGAE's predecessors (PRAE, PVAE) and successor (PTAE), on this package's parts.

PGAE paper, Sec. 2: PRAE (Yamada et al., RA-L 2018) and PVAE (Özdemir et al., ICDL 2021) bind two
separate autoencoders with a loss, and so must be configured per translation direction.

- ``binding``     the binding loss that pulls paired action and description codes together
- ``prae``        PRAE: two autoencoders bound by that loss, translating by their cross paths
- ``pvae``        PVAE: PRAE with a variational bottleneck per modality (means, log-variances, KL)
- ``train``       training PRAE and PVAE: both autoencoders at once, bound by the binding loss
- ``configured``  Table 1's cells of a model configured per direction, N.A. where it has no path
"""
