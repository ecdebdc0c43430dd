#!/usr/bin/env python3
"""The Ritter dry dam break (tests/terrain/sim_water_test.cpp, FloodRitterDryDamBreak) on a
NumPy replica of flood mode's 1-D scheme, to find what the front lag depends on
(docs/sim-water.md, "Known limits").

The replica: float64, minmod or MC reconstruction of h and u (first order at the walls), HLL with
Toro's dry-bed speeds (W14, W15), Heun (W22) with the depth clipped at 0 and the momentum of
cells at or below the dry depth zeroed, CFL step alpha dx / max(|u| + sqrt(g h)) (W10); on a
flat bed the hydrostatic reconstruction and the bed source vanish. It reproduces the solver's
figures (MC: relative L1 0.0016, front 15.4% / 10.6% behind at t = 10 / 20 s; minmod before the
outflow limits W25: 0.0025, 15.4% / 12.2%).

    /usr/bin/python3 tools/ritter_front_study.py            # variants at 1 m cells (~10 s)
    /usr/bin/python3 tools/ritter_front_study.py --refine   # 1 m to 1/16 m cells (~2 min)
    /usr/bin/python3 tools/ritter_front_study.py --long     # 10 s to 160 s, MC vs minmod (~5 s)
"""
import argparse

import numpy as np

G = 9.81


def minmod(a, b):
    return np.where(a * b <= 0, 0.0, np.where(np.abs(a) < np.abs(b), a, b))


def mc(a, b):
    return np.where(a * b <= 0, 0.0, np.sign(a) * np.minimum(np.minimum(2 * np.abs(a), 2 * np.abs(b)), 0.5 * np.abs(a + b)))


def run(cells_per_m=1, times=(10.0, 20.0), cfl=0.45, dry=1e-6, order2=True, limiter=minmod, u_limiter=None,
        toro=True, kp_eps=None, recon_q=False, first_u_near_thin=None, cfl_2c=False, length=400.0, x0=200.0):
    """Returns [(t, relative L1 of depth, front travel error)] for a channel of `length` m, h0 = 1 m."""
    n, dx = int(length) * cells_per_m, 1.0 / cells_per_m
    xc = (np.arange(n) + 0.5) * dx
    h = np.where(xc < x0, 1.0, 0.0)
    q = np.zeros(n)
    u_limiter = u_limiter or limiter

    def vel(h, q):
        if kp_eps is not None:  # Kurganov-Petrova desingularisation
            return np.sqrt(2) * h * q / np.sqrt(h**4 + np.maximum(h**4, kp_eps**4))
        return np.where(h > dry, q / np.where(h > dry, h, 1), 0.0)

    def rhs(h, q):
        u = vel(h, q)
        hm = np.concatenate([[h[0]], h, [h[-1]]])
        um = np.concatenate([[-u[0]], u, [-u[-1]]])
        sh, su = np.zeros(n), np.zeros(n)
        if order2:
            sh = limiter(hm[1:-1] - hm[:-2], hm[2:] - hm[1:-1])
            su = u_limiter(um[1:-1] - um[:-2], um[2:] - um[1:-1])
            sh[0] = sh[-1] = su[0] = su[-1] = 0
            if first_u_near_thin is not None:
                su = np.where(hm[1:-1] < first_u_near_thin * np.maximum(hm[:-2], hm[2:]), 0, su)
        hE, hW, uE, uW = h + 0.5 * sh, h - 0.5 * sh, u + 0.5 * su, u - 0.5 * su
        if recon_q and order2:
            qm = np.concatenate([[-q[0]], q, [-q[-1]]])
            sq = limiter(qm[1:-1] - qm[:-2], qm[2:] - qm[1:-1])
            sq[0] = sq[-1] = 0
            uE = np.where(hE > dry, (q + 0.5 * sq) / np.maximum(hE, 1e-30), 0)
            uW = np.where(hW > dry, (q - 0.5 * sq) / np.maximum(hW, 1e-30), 0)
        hL, uL = np.concatenate([[hW[0]], hE]), np.concatenate([[-uW[0]], uE])
        hR, uR = np.concatenate([hW, [hE[-1]]]), np.concatenate([uW, [-uE[-1]]])
        cL, cR = np.sqrt(G * hL), np.sqrt(G * hR)
        sL, sR = np.minimum(uL - cL, uR - cR), np.maximum(uL + cL, uR + cR)
        dl, dr = hL <= dry, hR <= dry
        if toro:
            sL, sR = np.where(dl, uR - 2 * cR, sL), np.where(dl, uR + cR, sR)
            sL, sR = np.where(dr, uL - cL, sL), np.where(dr, uL + 2 * cL, sR)
        qL, qR = hL * uL, hR * uR
        fL, fR = qL * uL + 0.5 * G * hL * hL, qR * uR + 0.5 * G * hR * hR
        den = np.where(sR - sL == 0, 1, sR - sL)
        Fh = np.where(sL >= 0, qL, np.where(sR <= 0, qR, (sR * qL - sL * qR + sL * sR * (hR - hL)) / den))
        Fq = np.where(sL >= 0, fL, np.where(sR <= 0, fR, (sR * fL - sL * fR + sL * sR * (qR - qL)) / den))
        Fh, Fq = np.where(dl & dr, 0, Fh), np.where(dl & dr, 0, Fq)
        return -(Fh[1:] - Fh[:-1]) / dx, -(Fq[1:] - Fq[:-1]) / dx

    t, out = 0.0, []
    for T in times:
        while t < T - 1e-9:
            u = vel(h, q)
            speed = np.max(np.abs(u) + (2 if cfl_2c else 1) * np.sqrt(G * h))
            dt = min(cfl * dx / speed, T - t)
            a, b = rhs(h, q)
            h1 = np.maximum(h + dt * a, 0)
            q1 = np.where(h1 <= dry, 0, q + dt * b)
            a1, b1 = rhs(h1, q1)
            h2 = np.maximum(h + 0.5 * dt * (a + a1), 0)
            q = np.where(h2 <= dry, 0, q + 0.5 * dt * (b + b1))
            h, t = h2, t + dt
        c0, xi = np.sqrt(G), xc - x0
        exact = np.where(xi > 2 * c0 * T, 0, np.where(xi > -c0 * T, (2 * c0 - xi / T) ** 2 / (9 * G), 1.0))
        l1 = np.sum(np.abs(h - exact)) / np.sum(exact)
        front = (np.nonzero(h > 1e-4)[0][-1] + 1) * dx  # downstream edge of the last cell deeper than 0.1 mm
        out.append((T, l1, abs((front - x0) - 2 * c0 * T) / (2 * c0 * T)))
    return out


def show(name, res):
    print(f"{name:44s} " + "  ".join(f"t={T:.0f} s: L1 {l1:.4f} front {fe * 100:5.1f}%" for T, l1, fe in res))


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--refine", action="store_true", help="grid refinement study instead of the variants")
    ap.add_argument("--long", action="store_true", help="the lag as the front crosses 63 to 1000 cells")
    args = ap.parse_args()
    if args.refine:
        for k in (1, 2, 4, 8, 16):
            show(f"dx = 1/{k} m", run(cells_per_m=k))
    elif args.long:
        # the channel of FloodRitterDryDamBreak's 5% check: 1560 m, dam at 520 m
        for name, lim in (("MC slopes", mc), ("minmod slopes (the default)", minmod)):
            show(name, run(limiter=lim, times=(10.0, 20.0, 40.0, 80.0, 120.0, 160.0), length=1560.0, x0=520.0))
    else:
        show("as the solver (minmod slopes)", run())
        show("MC slopes", run(limiter=mc))
        show("MC slopes on h, minmod on u", run(limiter=mc, u_limiter=minmod))
        show("first order", run(order2=False))
        for d in (1e-8, 1e-12, 0.0):
            show(f"dry depth {d:g}", run(dry=d))
        show("plain HLL speeds on dry sides", run(toro=False))
        show("CFL 0.1", run(cfl=0.1))
        show("CFL on |u| + 2c", run(cfl_2c=True))
        show("Kurganov-Petrova velocity, eps 1e-3", run(kp_eps=1e-3))
        show("reconstruct hu, not u", run(recon_q=True))
        show("first-order u where h < 0.5 x a neighbour", run(first_u_near_thin=0.5))
