"""The family: PGAE's predecessors (PRAE, PVAE) and successor (PTAE), on this package's parts.

PGAE paper, Sec. 2: PRAE (Yamada et al., RA-L 2018) and PVAE (Özdemir et al., ICDL 2021) bind two
separate autoencoders with a loss, and so must be configured per translation direction.
PGAE's successor PTAE is one model doing every task as PGAE does, trained by PGAE's loop: it is
:mod:`pgae_lite.model.ptae`, beside PGAE.

- ``binding``     the binding loss that pulls paired action and description codes together
- ``prae``        PRAE: two autoencoders bound by that loss, translating by their cross paths
- ``pvae``        PVAE: PRAE with a variational bottleneck per modality (means, log-variances, KL)
- ``train``       training PRAE, PVAE and PVAE-BERT (PVAE on the pretrained encoder, frozen or with its top
                  layer tuned): both autoencoders at once, bound by the binding loss
- ``configured``  Table 1's cells of a model configured per direction, N.A. where it has no path
"""
