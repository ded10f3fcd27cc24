"""Local methods and diagnostics from a saved iterate of the 1024-node crawl (issue 27, item 4;
docs/studies/large-interface-solve.md, "The crawl's iterate: a square-root branch of the law").

The iterates come from ``studies/powell_kinks.py`` with ``KINKS_SAVE=<folder>`` (one
``xNNN.npy`` per Powell iteration), e.g. the crawl of the first Jacobian's column norms:

    KINKS_SAVE=/tmp/kinks PYTHONPATH=$PWD/src OPENBLAS_NUM_THREADS=1 \
        python studies/powell_kinks.py 32 operator 0 60 norms=first
    KINKS_SAVE=/tmp/kinks/main ... python studies/powell_kinks.py 32 operator 0 60

and then, in a few seconds of CPU per method after the condensation (about 11 s):

    PYTHONPATH=$PWD/src OPENBLAS_NUM_THREADS=1 python studies/kinks_local.py 32 \
        /tmp/kinks/x056.npy fd,nodes,incr,gll1,newton,elim,trial [root.npy]

``fd``: the residual along the Newton step and along the gradient (scaled to the Newton
step's length) against its linear model, ``h`` from 1 to 1e-7, and the contact nodes whose
regime differs from the iterate's; ``nodes``: the nodes holding the residual and the
model's error; ``incr``: the slip increments and ``|pre_T| / (mu pre_N) - 1`` of the two
worst nodes at the iterate, on the Newton step and at the root; ``gllM``: Newton with a
backtracking line search against the largest ``|f|`` of the last M iterates (Grippo,
Lampariello and Lucidi 1986; M = 1 is Armijo's monotone search); ``newton``: full Newton
steps; ``elim``: nonlinear elimination (the worst nodes' balance solved alone by Powell on
their formed Jacobian, the others held, then a Newton step of the whole); ``trial``: the
Newton step from the iterate with the Jacobian of the trial point, its regime (a
primal-dual active set iteration on the regimes); ``rootjac``: the Newton step from the
iterate with the law's derivative ``G`` of the root (given as the last argument) at every
node, and at the two worst nodes only.
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..",
                                "benchmarks"))


def build(n):
    """The periodic problem of ``studies/powell_kinks.py`` (operator representation)."""
    from scale_3d import LOADS, H, condenser, pad, warm_up

    from fretwear.hb.connectors import connect
    from fretwear.hb.fourier import FourierBasis
    from fretwear.hb.penalty import penalty
    from fretwear.hb.preload import static_anchor
    from fretwear.hb.problem import DLFTProblem

    load = LOADS["slip"]
    warm_up(load)
    model = pad(n, load)
    basis = FourierBasis.up_to(H, 128)
    mc = condenser(model, load)
    mc.representation = "operator"
    red = mc.reduced(2 * np.pi * load.freq, basis.orders, frequency=load.freq)
    anchor = static_anchor(model, condenser=mc)
    red = connect(red, model.contact)
    eps = penalty("auto", model=model, reduced=red, condenser=mc)
    return DLFTProblem(red, model.contact, basis, eps=eps, anchor=anchor, jacobian="krylov")


class Probe:
    """The residual of ``prob`` on flat vectors, keeping the regimes of the last law."""

    def __init__(self, prob):
        self.prob, self.state = prob, None
        law = prob.time_law

        def kept(U):
            out = law(U)
            self.state = out[2].copy()
            return out

        prob.time_law = kept
        self.law = law

    def __call__(self, x, jac=True):
        p = self.prob
        return p.residual(x.reshape(p.m, p.H), jac)

    def scale(self, x):
        return self.prob.scale(x.reshape(self.prob.m, self.prob.H))

    def changed(self, ref):
        return np.flatnonzero(np.any(self.state != ref, axis=1))


def norm(x):
    return float(np.sqrt(np.dot(np.ravel(x), np.ravel(x))))


def per_node(v, nc):
    return np.sqrt(np.sum(np.reshape(v, (nc, -1)) ** 2, axis=1))


def fd(fun, x0):
    f, J = fun(x0)
    ref = fun.state.copy()
    s = -J.solve(f, rtol=1e-10)
    g = J.T @ f
    for name, d in (("newton", s), ("gradient", -g * (norm(s) / norm(g)))):
        Jd = J @ d
        for h in (1.0, 0.3, 0.1, 3e-2, 1e-2, 3e-3, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7):
            fh, _ = fun(x0 + h * d, False)
            chg = fun.changed(ref)
            err = norm((fh - f) / h - Jd) / norm(Jd)
            print(f"fd {name:8s} h {h:.0e} |f(x + h d)| {norm(fh):.3e} "
                  f"|(f(x + h d) - f) / h - J d| / |J d| {err:.3e} nodes changing "
                  f"{chg.size} {chg[:6]}", flush=True)


def nodes(fun, x0):
    prob = fun.prob
    f, J = fun(x0)
    ref = fun.state
    s = -J.solve(f, rtol=1e-10)
    Jd = J @ s
    fn = per_node(f, prob.nc)
    top = np.argsort(fn)[::-1][:6]
    print(f"nodes: |f| {norm(f):.3e}; largest per node {top} {fn[top]}; their share of "
          f"|f|^2 {np.sum(fn[top[:2]] ** 2) / norm(f) ** 2:.3f} (two)", flush=True)
    for h in (1e-3, 1e-4):
        fh, _ = fun(x0 + h * s, False)
        e = per_node((fh - f) / h - Jd, prob.nc)
        top = np.argsort(e)[::-1][:4]
        for p in top:
            print(f"  h {h:.0e} node {p}: model error {e[p]:.3e}, step "
                  f"{norm(s.reshape(prob.nc, -1)[p]):.3e}, regime samples sep/stick/slip "
                  f"{[int(np.sum(ref[p] == k)) for k in (0, 1, 2)]}", flush=True)


def incr(fun, x0, root):
    prob = fun.prob
    f, J = fun(x0)
    s = -J.solve(f, rtol=1e-8)
    worst = np.sort(np.argsort(per_node(f, prob.nc))[::-1][:2])
    points = [("iterate", x0), ("+1e-3 Newton", x0 + 1e-3 * s), ("+1e-2 Newton", x0 + 1e-2 * s)]
    if root is not None:
        points.append(("root", root))
        print(f"|iterate - root| {norm(x0 - root):.3e}, largest per node "
              f"{np.max(per_node(x0 - root, prob.nc)):.3e}, median "
              f"{np.median(per_node(x0 - root, prob.nc)):.3e}", flush=True)
    for name, x in points:
        lu, lx, st, _ = fun.law(x.reshape(prob.m, prob.H))
        for p in worst:
            sl = np.flatnonzero(st[p] == 2)
            inc = [norm(lx[p, 1:, k] - lx[p, 1:, k - 1]) for k in sl]
            over = [norm(lu[p, 1:, k] - lx[p, 1:, k - 1]) / (prob.mu[p] * lu[p, 0, k]) - 1
                    for k in sl]
            print(f"{name:13s} node {p}: slips at {sl}, increments {np.array(inc)} N, "
                  f"|pre_T|/(mu pre_N) - 1 {np.array(over)}", flush=True)


def newton_ls(fun, x, memory, max_iter=12, label=""):
    """Newton's steps (GMRES to 1e-10), backtracking against the largest ``|f|`` of the last
    ``memory`` iterates; memory 0: full steps."""
    c0 = time.process_time()
    f, J = fun(x)
    fn, hist = norm(f), [norm(f)]
    for k in range(max_iter):
        if fn <= 1e-8 * fun.scale(x):
            break
        s = -J.solve(f, rtol=1e-10)
        t, ref = 1.0, max(hist[-max(memory, 1):])
        while True:
            fnew, _ = fun(x + t * s, False)
            if memory == 0 or norm(fnew) <= (1 - 1e-4 * t) * ref or t < 1e-4:
                break
            t *= 0.5
        print(f"{label} {k}: |f| {fn:.3e}, step {t:.3g}, |f| there {norm(fnew):.3e}",
              flush=True)
        x = x + t * s
        f, J = fun(x)
        fn = norm(f)
        hist.append(fn)
    print(f"{label} end: |f| {fn:.3e}, relative {fn / fun.scale(x):.2e}, "
          f"{time.process_time() - c0:.1f} s CPU", flush=True)


def subproblem(prob, U, nodes):
    """The balance of ``nodes`` alone at ``U`` (m, H), the others held: ``(fun, x0,
    dofs)``; ``lambda_u`` of those rows is linear in their own unknowns (eq. 23)."""
    from fretwear.hb import contact as law
    from fretwear.hb.reduce import to_real_blocks

    d, H = prob.d, prob.H
    dofs = (nodes[:, None] * d + np.arange(d)).reshape(-1)
    lam0 = prob.lambda_u(U)[dofs].reshape(-1)
    U0 = np.array(U[dofs], dtype=float).reshape(-1)
    Z = prob.reduced.Z
    Zc = (Z[:, dofs][:, :, dofs] if isinstance(Z, np.ndarray)
          else np.stack([Z.block(b, rows=dofs, cols=dofs) for b in range(len(Z))]))
    A = prob.eps * np.eye(dofs.size * H) - to_real_blocks(Zc, prob.reduced.orders)
    W = prob.W[dofs].reshape(-1)
    mu, start = prob.mu[nodes].copy(), np.ascontiguousarray(prob.eps * prob.anchor[nodes])
    normal = None if prob.normal is None else prob.normal[nodes]
    k, n = nodes.size, dofs.size * H

    def fun(x, jac=True):
        lam = lam0 + A @ (x - U0)
        lu = np.ascontiguousarray(prob.basis.to_time(lam.reshape(k * d, H)).reshape(k, d, -1))
        lx, state, _ = law.dlft_time(lu, mu, start, prob.tol, prob.max_sweeps, normal)
        f = prob.eps * (x - W) - prob.basis.to_freq(lx.reshape(k * d, -1)).reshape(-1)
        if not jac:
            return f, None
        G = law.dlft_jacobian(lu, lx, state, mu, prob.P, prob.Q, start, prob.tol,
                              prob.max_sweeps, normal)
        return f, prob.eps * np.eye(n) - np.matmul(G, A.reshape(k, d * H, n)).reshape(n, n)

    return fun, U0, dofs


def elim(fun, x, steps=4):
    from fretwear.hb import solvers

    prob = fun.prob
    solvers.WATCHDOG_FORMED = True
    f, _ = fun(x)
    for k in range(steps):
        per = per_node(f, prob.nc) ** 2
        order = np.argsort(per)[::-1]
        worst = np.sort(order[:int(np.searchsorted(np.cumsum(per[order]),
                                                   0.999 * per.sum())) + 1][:32])
        sub, x0, dofs = subproblem(prob, x.reshape(prob.m, prob.H), worst)
        before = norm(sub(x0, False)[0])
        xs, fs, st = solvers.powell(sub, x0, lambda _: 1.0, tol=1e-3 * before, max_iter=500)
        x = x.copy()
        x.reshape(prob.m, prob.H)[dofs] = xs.reshape(dofs.size, prob.H)
        f, J = fun(x)
        print(f"elim {k}: nodes {worst}, their |f| {before:.3e} -> {norm(fs):.3e} "
              f"({st.iterations} Powell iterations); whole |f| {norm(f):.3e}", flush=True)
        x = x - J.solve(f, rtol=1e-6)
        f, _ = fun(x)
        print(f"elim {k}: after a Newton step of the whole |f| {norm(f):.3e}", flush=True)


def trial(fun, x, tries=4):
    f, J = fun(x)
    fn, ref = norm(f), fun.state.copy()
    s = -J.solve(f, rtol=1e-8)
    for r in range(tries):
        ft, Jt = fun(x + s)
        print(f"trial {r}: |f| {fn:.3e}, at the trial point {norm(ft):.3e}, nodes changing "
              f"{fun.changed(ref).size}", flush=True)
        if norm(ft) < fn:
            return
        s = -Jt.solve(f, rtol=1e-8)


def rootjac(fun, x0, root):
    from fretwear.hb import contact as law
    from fretwear.hb.krylov import KrylovJacobian

    prob = fun.prob

    def G(x):
        lu, lx, st, _ = fun.law(x.reshape(prob.m, prob.H))
        return law.dlft_jacobian(lu, lx, st, prob.mu, prob.P, prob.Q, prob.eps * prob.anchor,
                                 prob.tol, prob.max_sweeps, prob.normal)

    f, _ = fun(x0)
    Gx, Gr = G(x0), G(root)
    worst = np.argsort(per_node(f, prob.nc))[::-1][:2]
    mixed = Gx.copy()
    mixed[worst] = Gr[worst]
    for name, g in (("at every node", Gr), (f"at nodes {np.sort(worst)}", mixed)):
        s = -KrylovJacobian(g, prob.blocks, prob.eps, prob.d, owner=prob).solve(f, rtol=1e-10)
        ft, _ = fun(x0 + s, False)
        print(f"rootjac, the root's G {name}: |f| {norm(f):.3e} -> {norm(ft):.3e}, distance "
              f"to the root {norm(x0 - root):.3e} -> {norm(x0 + s - root):.3e}", flush=True)


def phase(fun, x, settings=""):
    """``fretwear.hb.kinks.local_phase`` from ``x`` as Powell calls it (its ``target`` the
    periodic test's), the module's constants set from ``settings`` (``NAME=value;...``):
    its rounds, its CPU seconds split into the eliminations and the rest."""
    from fretwear.hb import kinks
    from fretwear.hb.options import PERIODIC

    saved = {}
    for item in filter(None, settings.split(";")):
        name, value = item.split("=")
        saved[name] = getattr(kinks, name)
        setattr(kinks, name, type(saved[name])(float(value)))
    prob, record = fun.prob, []
    spent = {"elim": 0.0}
    eliminate = kinks.eliminate

    def timed(*a, **k):
        c = time.process_time()
        out = eliminate(*a, **k)
        spent["elim"] += time.process_time() - c
        return out

    kinks.eliminate = timed
    f, _ = fun(x, False)
    target = PERIODIC.tol * fun.scale(x)
    c0 = time.process_time()
    xl = kinks.local_phase(prob, record)(x, f, target)
    cpu = time.process_time() - c0
    kinks.eliminate = eliminate
    for name, value in saved.items():
        setattr(kinks, name, value)
    for rep, fe, fn in record:
        print(f"phase [{settings}]: {rep.nodes.size} nodes, their |f| {rep.before:.3e} -> "
              f"{rep.after:.3e} ({rep.iterations} Powell), whole {fe:.3e}, after the Newton "
              f"step {fn:.3e}", flush=True)
    print(f"phase [{settings}]: |f| {norm(f):.3e} -> {norm(fun(xl, False)[0]):.3e} (target "
          f"{target:.3e}), {len(record)} rounds, {cpu:.1f} s CPU ({spent['elim']:.1f} s in "
          f"the eliminations)", flush=True)


def main():
    n, paths, methods = int(sys.argv[1]), sys.argv[2], sys.argv[3].split(",")
    root = np.load(sys.argv[4]) if len(sys.argv) > 4 else None
    fun = Probe(build(n))
    for path in paths.split(","):
        run(fun, path, methods, root)


def run(fun, path, methods, root):
    x0 = np.load(path)
    print(f"{path}: |f| {norm(fun(x0, False)[0]):.3e}", flush=True)
    for m in methods:
        if m.startswith("phase"):  # phase or phase:NAME=value;NAME=value
            phase(fun, x0.copy(), m[6:])
        elif m == "fd":
            fd(fun, x0)
        elif m == "nodes":
            nodes(fun, x0)
        elif m == "incr":
            incr(fun, x0, root)
        elif m.startswith("gll"):
            newton_ls(fun, x0.copy(), int(m[3:]), label=m)
        elif m == "newton":
            newton_ls(fun, x0.copy(), 0, max_iter=6, label=m)
        elif m == "elim":
            elim(fun, x0.copy())
        elif m == "trial":
            trial(fun, x0.copy())
        elif m == "rootjac":
            rootjac(fun, x0, root)


if __name__ == "__main__":
    main()
