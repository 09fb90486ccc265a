"""How the multigrid's coarse space sets the PPE's Krylov iterations, on an assembled matrix.

The SPH Laplacian of Eq. (27) (quintic, h = 1.2 dx, support 3h, η² = 0.01 h²) on a lattice
perturbed by ±0.1 dx, a water column with its top layer at P = 0 (Dirichlet) and Neumann walls,
solved from zero by CG and BiCGSTAB (scipy) with: Jacobi; the additive two-level preconditioner
isph uses, z = D⁻¹r + s P A_c⁻¹ Pᵀ r, with piecewise-constant aggregates (P0) of B × B (× B)
particles; the same with a piecewise-linear discontinuous coarse space (P1: 1, x, y (, z) per
aggregate); and the multiplicative cycle. The coarse problem is solved exactly (sparse LU), so
the counts bound what a V-cycle reaches. docs/performance.md, "The pressure solve", quotes it.

Usage: python3 tools/multigrid_prototype.py [2d|2dbig|3d|3dbig|all]  (needs numpy and scipy;
single-threaded, about 20 minutes for `all`).
"""
import os
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
import sys, time
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.spatial import cKDTree

DX = 1.0
H = 1.2 * DX
SUPPORT = 3.0 * H
ETA2 = 0.01 * H * H


def dWdr(r, dim):
    q = r / H
    t = lambda a: np.where(q < a, (a - q) ** 4, 0.0)
    # d/dq of (3-q)^5 - 6(2-q)^5 + 15(1-q)^5
    dq = -5 * t(3.0) + 30 * t(2.0) - 75 * t(1.0)
    alpha = 7.0 / (478.0 * np.pi * H ** 2) if dim == 2 else 1.0 / (120.0 * np.pi * H ** 3)
    return alpha * dq / H  # <= 0


def build(shape, seed=1234):
    """shape = (nx, ny) or (nx, ny, nz); last axis vertical, top layer Dirichlet."""
    dim = len(shape)
    rng = np.random.default_rng(seed)
    idx = np.indices(shape).reshape(dim, -1).T  # lattice indices
    pos = idx * DX + rng.uniform(-0.1, 0.1, size=idx.shape) * DX
    N = pos.shape[0]
    V = DX ** dim
    tree = cKDTree(pos)
    pairs = tree.query_pairs(SUPPORT, output_type="ndarray")
    i, j = pairs[:, 0], pairs[:, 1]
    rij = pos[i] - pos[j]
    r = np.linalg.norm(rij, axis=1)
    F = r * dWdr(r, dim) / (r * r + ETA2)  # r.gradW/(r^2+eta^2) < 0
    w = 2.0 * V * np.abs(F)               # -a_ij
    # full A (both directions), diagonal = sum of |offdiag| over ALL neighbours
    Afull = sp.coo_matrix((np.r_[-w, -w], (np.r_[i, j], np.r_[j, i])), shape=(N, N)).tocsr()
    diag = -np.asarray(Afull.sum(axis=1)).ravel()
    Afull = Afull + sp.diags(diag)
    dirichlet = idx[:, -1] == shape[-1] - 1
    free = np.where(~dirichlet)[0]
    A = Afull[free][:, free].tocsr()
    return A, pos[free], idx[free], shape


def aggregates(idx, B):
    """square/cubic blocks of side B in lattice index space."""
    blk = idx // B
    _, agg = np.unique(blk, axis=0, return_inverse=True)
    return agg.ravel()


def prolongator(pos, idx, B, kind):
    agg = aggregates(idx, B)
    n = len(agg)
    nagg = agg.max() + 1
    if kind == "P0":
        P = sp.csr_matrix((np.ones(n), (np.arange(n), agg)), shape=(n, nagg))
        return P
    # P1 discontinuous: 1, (x-cx)/B, (y-cy)/B, [(z-cz)/B] per aggregate, locally orthonormalised
    dim = pos.shape[1]
    order = np.argsort(agg, kind="stable")
    starts = np.searchsorted(agg[order], np.arange(nagg + 1))
    rows, cols, vals = [], [], []
    col = 0
    for a in range(nagg):
        mem = order[starts[a]:starts[a + 1]]
        X = pos[mem]
        c = X.mean(axis=0)
        Q0 = np.column_stack([np.ones(len(mem)), (X - c) / B])
        Q, R = np.linalg.qr(Q0)
        keep = np.abs(np.diag(R)) > 1e-8 * abs(R[0, 0])
        Q = Q[:, keep]
        for k in range(Q.shape[1]):
            rows.append(mem); cols.append(np.full(len(mem), col)); vals.append(Q[:, k])
            col += 1
    P = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(n, col))
    return P


class Counter:
    def __init__(self, f):
        self.f = f; self.n = 0
    def __call__(self, x):
        self.n += 1
        return self.f(x)


def make_precs(A, P, s_list):
    Dinv = 1.0 / A.diagonal()
    Ac = (P.T @ A @ P).tocsc()
    lu = spla.splu(Ac)
    out = {}
    for s in s_list:
        def f(r, s=s):
            return Dinv * r + s * (P @ lu.solve(P.T @ r))
        out[s] = f
    info = dict(nc=Ac.shape[0], nnzrow=Ac.nnz / Ac.shape[0], opc=Ac.nnz / A.nnz)
    return out, info, lu, Dinv


def mult_prec(A, P, lu, Dinv, omega=0.7):
    def f(r):
        x = omega * Dinv * r
        x = x + P @ lu.solve(P.T @ (r - A @ x))
        x = x + omega * Dinv * (r - A @ x)
        return x
    return f


def solve(A, b, Mfun, method, tol, maxiter=3000):
    n = A.shape[0]
    Mc = Counter(Mfun) if Mfun is not None else None
    M = spla.LinearOperator((n, n), matvec=Mc) if Mc else None
    cb = [0]
    def callback(xk):
        cb[0] += 1
    fn = spla.cg if method == "cg" else spla.bicgstab
    x, info = fn(A, b, rtol=tol, atol=0.0, maxiter=maxiter, M=M, callback=callback)
    rel = np.linalg.norm(b - A @ x) / np.linalg.norm(b)
    if method == "cg":
        it = cb[0]
    else:
        # scipy bicgstab calls callback once per full iteration; an exit at the half step
        # (s small) happens without callback -> count it as +0.5
        napp = Mc.n if Mc else None
        it = cb[0] if napp is None else napp / 2.0
    return it, info, rel


def run_case(shape, Bs0=(2, 3, 4, 6, 8), Bs1=(2, 4, 8), s_list=(0.5, 0.85, 1.0, 1.3), mult_Bs=(2, 3, 4, 6, 8)):
    t0 = time.time()
    A, pos, idx, shape = build(shape)
    n = A.shape[0]
    dim = len(shape)
    print(f"\n=== domain {shape} (dim {dim}): unknowns {n}, nnz/row {A.nnz / n:.1f} ===", flush=True)
    # sanity: symmetry & positive definiteness (smallest eig)
    asym = abs(A - A.T).max()
    lmin = spla.eigsh(A, k=1, sigma=0, which="LM", return_eigenvectors=False)[0]
    print(f"  max|A-A^T| = {asym:.2e}, lambda_min(A) = {lmin:.3e}, max diag = {A.diagonal().max():.3e}")
    rng = np.random.default_rng(42)
    b_rand = rng.standard_normal(n)
    x, y = pos[:, 0], pos[:, -1]
    Lx, Ly = shape[0] * DX, shape[-1] * DX
    b_smooth = np.sin(np.pi * (x + 0.5) / Lx) * np.cos(np.pi * (y + 0.5) / (2 * Ly)) \
        + 0.3 * np.sin(3 * np.pi * (x + 0.5) / Lx) * np.sin(2 * np.pi * (y + 0.5) / Ly)
    if dim == 3:
        b_smooth = b_smooth * np.sin(np.pi * (pos[:, 1] + 0.5) / (shape[1] * DX))
    rhs = {"rand": b_rand, "smooth": b_smooth}
    tols = (1e-4, 1e-6)
    results = []  # (label, B, s, rhsname, method, tol, iters, info)

    def do(label, B, s, Mfun):
        row = {}
        for rn, b in rhs.items():
            for m in ("cg", "bicgstab"):
                for tol in tols:
                    it, info, rel = solve(A, b, Mfun, m, tol)
                    row[(rn, m, tol)] = (it, info, rel)
        results.append((label, B, s, row))
        return row

    def fmt(row, rn):
        def c(v):
            it, info, rel = v
            return f"{it:g}" + ("" if info == 0 else "!")
        return " ".join(f"{c(row[(rn, m, t)]):>7}" for m in ("cg", "bicgstab") for t in tols)

    hdr = f"{'prec':<14}{'B':>3}{'s':>6} {'nc':>6}{'nnz/r':>7} | rhs  | {'cg4':>7} {'cg6':>7} {'bi4':>7} {'bi6':>7}"
    print(hdr)
    row = do("jacobi", "-", "-", lambda r, d=1.0 / A.diagonal(): d * r)
    for rn in rhs:
        print(f"{'jacobi':<14}{'-':>3}{'-':>6} {'-':>6}{'-':>7} | {rn:<5}| {fmt(row, rn)}", flush=True)
    best = {}
    for kind, Bs in (("P0", Bs0), ("P1", Bs1)):
        for B in Bs:
            P = prolongator(pos, idx, B, kind)
            precs, info, lu, Dinv = make_precs(A, P, s_list)
            scores = {}
            for s in s_list:
                row = do(f"add-{kind}", B, s, precs[s])
                for rn in rhs:
                    print(f"{'add-' + kind:<14}{B:>3}{s:>6} {info['nc']:>6}{info['nnzrow']:>7.1f} | {rn:<5}| {fmt(row, rn)}", flush=True)
                scores[s] = sum(row[("rand", m, t)][0] for m in ("cg", "bicgstab") for t in tols)
            sbest = min(scores, key=scores.get)
            best[(kind, B)] = (sbest, info)
            print(f"    ({kind} B={B}: coarse nnz / fine nnz = {info['opc']:.3f})")
            if (kind == "P0" and B in mult_Bs) or (kind == "P1" and B == 4):
                row = do(f"mult-{kind}", B, "-", mult_prec(A, P, lu, Dinv))
                for rn in rhs:
                    print(f"{'mult-' + kind + '(w.7)':<14}{B:>3}{'-':>6} {info['nc']:>6}{info['nnzrow']:>7.1f} | {rn:<5}| {fmt(row, rn)}", flush=True)
    # summary with best s (random rhs)
    print(f"\n--- summary {shape}, random rhs, best s per (kind,B) chosen by sum of the 4 rand-rhs counts ---")
    print(f"{'prec':<10}{'B':>3}{'best s':>7}{'nc':>7}{'nnz/r':>7} | {'cg 1e-4':>8}{'cg 1e-6':>8}{'bi 1e-4':>8}{'bi 1e-6':>8}")
    for (label, B, s, row) in results:
        if label == "jacobi" or label.startswith("mult") or best.get((label[4:], B), (None,))[0] == s:
            if label == "jacobi":
                nc, nr, ss = "-", "-", "-"
            else:
                kind = label.split("-")[1]
                inf = best[(kind, B)][1]
                nc, nr, ss = inf["nc"], f"{inf['nnzrow']:.1f}", s
            vals = "".join(f"{row[('rand', m, t)][0]:>8g}" for m in ("cg", "bicgstab") for t in tols)
            print(f"{label:<10}{B:>3}{str(ss):>7}{str(nc):>7}{nr:>7} | {vals}")
    print(f"  (case time {time.time() - t0:.1f}s)", flush=True)


if __name__ == "__main__":
    mode = sys.argv[1] if len(sys.argv) > 1 else "all"
    print("legend: iteration counts; '!' = not converged (info != 0); bicgstab count = "
          "preconditioner applications / 2 (= scipy callback count, +0.5 if exit at half step)")
    if mode in ("2d", "all"):
        run_case((60, 60))
        run_case((120, 60))
    if mode in ("2dbig", "all"):
        run_case((240, 120))
    if mode in ("3d", "all"):
        run_case((16, 16, 16), Bs0=(2, 3, 4), Bs1=(2, 4), s_list=(0.5, 0.85, 1.0, 1.3), mult_Bs=(2, 4))
    if mode in ("3dbig", "all"):
        run_case((24, 24, 24), Bs0=(2, 3, 4, 6), Bs1=(2, 4), s_list=(0.85, 1.0, 1.3), mult_Bs=(2, 4))
