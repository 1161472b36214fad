#!/usr/bin/python3
"""Plane mean-curvature profile ([CMLS §4], Figures 3 and 5): the plate of
make_cases.py (~1,100 vertices), its central disc lifted by 0.2, the border fixed; pure
bending and pure stretching.
  ground truth: the mesh-based shell of section 3 (eq. 10: gamma_s K + gamma_b K M^-1 K +
                gamma_f F, cotangent stiffness K, lumped mass M), scipy sparse solve;
  rbf-tri/bi:   the subspace of eq. 11 spanned by 1,000 global RBFs |x - c|^3 / |x - c|
                (centres: the farthest-point vertices), same energy, dense solve;
  mls:          `cadmorph deform --method mls` (spatial energies of section 5, 1,000 samples).
Prints the mean curvature H = |lap x| / 2 averaged over x bins of the strip |y - 0.5| < 0.03,
and the RMS of H - H_truth over interior vertices. Also checks cadmorph's mean_curvature
field against this script's H of the same mesh. Writes the profiles (20 bins) to
WORK_DIR/plane_profile_bending.csv and _stretching.csv (series,x,y,style) for mls_plot.
usage: plane_profile.py CADMORPH WORK_DIR"""
import subprocess, sys, os, time
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spl
import meshio

cad, work = sys.argv[1], sys.argv[2]
os.chdir(work)
m = meshio.read("plane.msh")
X = m.points.astype(float)
T = np.vstack([c.data for c in m.cells if c.type == "triangle"])
n = len(X)

def cot_matrices(X):
    I, J, V = [], [], []
    A = np.zeros(n)
    for q in range(3):
        i, j, k = T[:, q], T[:, (q + 1) % 3], T[:, (q + 2) % 3]
        u, w = X[j] - X[i], X[k] - X[i]
        cr = np.linalg.norm(np.cross(u, w), axis=1)
        cot = np.einsum("ij,ij->i", u, w) / cr
        # the angle at i weighs edge (j, k)
        I += [j, k, j, k]; J += [k, j, j, k]; V += [-0.5 * cot, -0.5 * cot, 0.5 * cot, 0.5 * cot]
        np.add.at(A, i, cr / 6)
    K = sp.csr_matrix((np.concatenate(V), (np.concatenate(I), np.concatenate(J))), shape=(n, n))
    return K, A  # K: positive semi-definite stiffness, lap x = -M^-1 K x

def mean_curvature(Y):
    K, A = cot_matrices(Y)
    L = -(K @ Y) / A[:, None]
    return 0.5 * np.linalg.norm(L, axis=1)

border = np.zeros(n, bool)
E = np.sort(np.vstack([T[:, [0, 1]], T[:, [1, 2]], T[:, [2, 0]]]), axis=1)
u, cnt = np.unique(E, axis=0, return_counts=True)
border[u[cnt == 1].ravel()] = True

def read_table(path, cols):
    a = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return a[:, 0].astype(int), a[:, 1:cols]

hid, hd = read_table("plane_H.csv", 4)
fid = np.loadtxt("plane_F.csv", skiprows=1, dtype=int)
dbar = np.zeros((n, 3)); dbar[hid] = hd
con = np.zeros(n, bool); con[hid] = True; con[fid] = True

K, A = cot_matrices(X)
Minv = sp.diags(1 / A)
F = sp.diags(np.where(con, A, 0.0))
gf = 1e9  # the ground truth meets its constraints (A_i ~ 1e-3, bending stiffness ~ 1e3)

def system(gs, gb):
    return gs * K + gb * (K @ Minv @ K) + gf * F

def farthest(k):
    idx = [int(np.argmin(np.linalg.norm(X - 0.5, axis=1)))]
    d = np.linalg.norm(X - X[idx[0]], axis=1)
    for _ in range(k - 1):
        idx.append(int(np.argmax(d)))
        d = np.minimum(d, np.linalg.norm(X - X[idx[-1]], axis=1))
    return np.array(idx)

C = X[farthest(1000)]
R = np.linalg.norm(X[:, None, :] - C[None, :, :], axis=2)
rows = []
strip = (np.abs(X[:, 1] - 0.5) < 0.03) & ~border
bins = np.linspace(0, 1, 11)
for label, gs, gb in (("bending", 0.0, 1.0), ("stretching", 1.0, 0.0)):
    S = system(gs, gb).tocsc()
    rhs = gf * (F @ dbar)
    t = time.time(); d_true = spl.spsolve(S, rhs); t_true = time.time() - t
    H_true = mean_curvature(X + d_true)
    res = {"truth (shell, eq. 10)": (H_true, t_true)}
    for name, Phi in (("rbf-tri subspace", R ** 3), ("rbf-bi subspace", R)):
        t = time.time()
        w = np.linalg.solve(Phi.T @ (S @ Phi), Phi.T @ rhs)
        res[name] = (mean_curvature(X + Phi @ w), time.time() - t)
    out = "plane_mls_%s.vtu" % label
    t = time.time()
    subprocess.run([cad, "deform", "--mesh", "plane.msh", "--handles", "plane_H.csv", "--fixed",
                    "plane_F.csv", "--method", "mls", "--stretch", str(gs), "--bend", str(gb),
                    "--samples", "1000", "-o", out], check=True, stdout=subprocess.DEVNULL)
    t_mls = time.time() - t
    mm = meshio.read(out)
    H_mls = mean_curvature(mm.points.astype(float))
    field_err = np.max(np.abs(H_mls - np.ravel(mm.point_data["mean_curvature"]))[~border])
    res["mls (cadmorph, s = 5)"] = (H_mls, t_mls)
    print("## %s (cadmorph's mean_curvature field vs this script: max |diff| %.2e)" % (label, field_err))
    print("| method | " + " | ".join("x~%.2f" % (0.5 * (bins[i] + bins[i + 1])) for i in range(10)) +
          " | RMS(H - H_truth) | max H | time s |")
    print("|---" * 14 + "|")
    fine = np.linspace(0, 1, 21)
    with open("plane_profile_%s.csv" % label, "w") as f:
        f.write("series,x,y,style\n")
        for name, (H, tt) in res.items():
            for i in range(20):
                sel = strip & (X[:, 0] >= fine[i]) & (X[:, 0] < fine[i + 1])
                if sel.any():
                    f.write("%s,%.3f,%.6g,%s\n" % (name.replace(",", ";"), 0.5 * (fine[i] + fine[i + 1]), np.mean(H[sel]),
                                                  "solid+markers" if name.startswith("truth") else "dashed+markers"))
    for name, (H, tt) in res.items():
        prof = [np.mean(H[strip & (X[:, 0] >= bins[i]) & (X[:, 0] < bins[i + 1])]) for i in range(10)]
        rms = np.sqrt(np.mean((H - H_true)[~border] ** 2))
        print("| %s | " % name + " | ".join("%.3f" % p for p in prof) +
              " | %.3f | %.3f | %.2f |" % (rms, np.max(H[~border]), tt))
    print()
