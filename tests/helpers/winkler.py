"""A rigid punch on a Winkler bed of springs rubbed by a tangential load: the analytic
worn state of tests/wear/test_worn_state.py and tests/wear/test_stick_set.py (moved from the
first)."""

from __future__ import annotations

import numpy as np

from fretwear.hb.fourier import FourierBasis
from fretwear.model.core import Load
from fretwear.model.matrices import ContactDofs, from_matrices

KN, KT, MU, T, AREA, KW = 1e8, 1e8, 0.5, 2.0, 1e-6, 1e-12
F = np.array([1.0, 2.0, 3.0, 5.0, 8.0, 12.0])  # normal loads [N]: mu F < T on the first three
BASIS = FourierBasis.up_to(1, 64)


def winkler(punch_load: float | None = None):
    """Six contact nodes in 3D, each a normal DOF on a spring ``KN`` and two tangential DOFs
    on springs ``KT``; loaded by ``F`` (normal, static) and ``T sin`` (first tangential).
    With ``punch_load``, the normal springs join a punch DOF (index 0) loaded by it instead
    of the nodes' own loads (a rigid punch under a force)."""
    nc = F.size
    off = 1 if punch_load is not None else 0
    n = off + 3 * nc
    K = np.zeros((n, n))
    fn, ft = np.zeros(n), np.zeros(n)
    normal = off + 3 * np.arange(nc)
    tang = np.stack([normal + 1, normal + 2], axis=1)
    for p in range(nc):
        i = normal[p]
        K[i, i] += KN
        if punch_load is not None:
            K[0, 0] += KN
            K[0, i] -= KN
            K[i, 0] -= KN
        else:
            fn[i] = F[p]
        for j in tang[p]:
            K[j, j] = KT
        ft[tang[p, 0]] = T
    if punch_load is not None:
        fn[0] = punch_load
    contact = ContactDofs(normal_dofs=normal, tangential_dofs=tang, mu=MU, gap=0.0, area=AREA,
                          wear_coefficient=KW,
                          coords=np.stack([np.arange(nc) * 1e-3, np.zeros(nc),
                                           np.zeros(nc)], axis=1))
    loads = [Load(fn, "constant", name="P"), Load(ft, "sin", name="T")]
    return from_matrices(K, np.eye(n), contact=contact, loads=loads)
