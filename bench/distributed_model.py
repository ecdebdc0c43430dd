#!/usr/bin/env python3
"""Scaling model of the distributed run (sim::DistributedSolver) on GPUs: docs/distributed.md.

A model, not a measurement: it prints the tables of docs/distributed.md from the figures below,
each with where it comes from. Run: python3 bench/distributed_model.py

One step of one GPU's block (w x h interior cells, an 8-cell halo on each side):
  compute   (w + 16)(h + 16) t_cell                         the halo is computed too
  halo      B = (2 * 8 (w + h) + 4 * 64) * 36 bytes          received (and as much sent)
  exchange  GL transfers (down and up) + network + latency  (one message per neighbour, 8)
  reduce    2 ceil(log2 P) alpha_reduce                      the wave speed's MPI_Allreduce
Step = compute + exchange + reduce (one block per GPU: nothing to overlap with), or
max(compute, exchange) + reduce with the exchange hidden behind other blocks (several per GPU).
"""
import math

# --- Figures and where they come from -------------------------------------------------------
SEED_MS_8192x4096 = 100.0  # the seed's GL solver, one GPU, 8192 x 4096 flood step (issue 18)
BYTES_PER_CELL_STEP = 344  # flood mode, what the kernels read and write (docs/benchmarks.md)
HBM_BPS = 3.35e12  # H100 SXM HBM3 bandwidth (NVIDIA H100 datasheet)
HBM_EFFICIENCY = 0.7  # fraction of it memory-bound kernels reach (assumption)
GPU_MEMORY = 80e9  # H100 SXM (datasheet); usable: 85% (assumption)
BYTES_PER_CELL_MEMORY = 176  # GL flood mode: 738 MB at 2048^2 (docs/benchmarks.md)
HALO = 8  # cells (TileOptions::halo: one step reads 7 away)
HALO_BYTES_PER_CELL = 28  # a water-only flood: state 16 + carried accumulators 12 (haloParts; bench_sim_mpi)
NET_BPS = 50e9  # InfiniBand NDR 400 Gb/s, one adapter per GPU (DGX H100 datasheet)
NET_LATENCY = 2e-6  # MPI message over NDR, one way (typical ping-pong half round trip; assumption)
REDUCE_STAGE = 2e-6  # one recursive-doubling stage of an 8-byte MPI_Allreduce (assumption)
PCIE_BPS = 25e9  # GL buffer read/write through host memory: PCIe Gen5 x16 is 64 GB/s, GL
#                 readbacks through a staging copy reach about 40% of it (assumption)
GL_CALL = 10e-6  # one glGetNamedBufferSubData / glNamedBufferSubData on a small range incl. its
#                 synchronisation (assumption: no GPU was available to measure it)
PARTS = 2  # GL transfers per halo piece: the state and the carried accumulators


def split(w, h, p):
    """px x py blocks (px * py = p) with the least halo (near-square blocks)."""
    best = None
    for px in range(1, p + 1):
        if p % px:
            continue
        py = p // px
        bw, bh = math.ceil(w / px), math.ceil(h / py)
        perim = bw + bh
        if best is None or perim < best[0]:
            best = (perim, px, py, bw, bh)
    return best[1:]


def step_ms(w, h, p, t_cell, transfer):
    px, py, bw, bh = split(w, h, p)
    cells = (bw + 2 * HALO) * (bh + 2 * HALO) if p > 1 else w * h
    compute = cells * t_cell
    if p == 1:
        return dict(block=f"{w}x{h}", compute=compute * 1e3, exchange=0, reduce=0, total=compute * 1e3,
                    halo_bytes=0, mem=w * h * BYTES_PER_CELL_MEMORY)
    nx = min(px - 1, 2)  # neighbours of an inner block (fewer at the region's edge)
    ny = min(py - 1, 2)
    side_cells = HALO * (bh * nx + bw * ny)
    corner_cells = HALO * HALO * nx * ny
    halo_bytes = (side_cells + corner_cells) * HALO_BYTES_PER_CELL
    messages = nx + ny + nx * ny
    if transfer == "rows":  # GlSolver before this branch: a strip moved row by row
        calls = PARTS * (HALO * (ny + nx * ny) + bh * nx) * 2  # down and up
    elif transfer == "packed":  # now: one transfer per piece and part (copy_rect.comp packs it)
        calls = PARTS * messages * 2
    else:  # "direct" (not built): GPU-resident halos, GPU-aware MPI (NVLink / GPUDirect RDMA)
        calls = 0
    gl = calls * GL_CALL + (2 * halo_bytes / PCIE_BPS if transfer != "direct" else 0)
    net = messages * NET_LATENCY + halo_bytes / NET_BPS
    exchange = gl + net
    reduce = 2 * math.ceil(math.log2(p)) * REDUCE_STAGE
    return dict(block=f"{bw}x{bh}", compute=compute * 1e3, exchange=exchange * 1e3, reduce=reduce * 1e3,
                total=(compute + exchange + reduce) * 1e3, halo_bytes=halo_bytes,
                mem=(bw + 2 * HALO) * (bh + 2 * HALO) * BYTES_PER_CELL_MEMORY,
                overlapped=(max(compute, exchange) + reduce) * 1e3)


def table(title, w, h, gpus, t_cell, transfers):
    print(f"\n### {title}\n")
    print("| GPUs | block | GB per GPU | compute ms | " + " | ".join(f"exchange ms ({t})" for t in transfers) +
          " | reduce ms | " + " | ".join(f"step ms ({t})" for t in transfers) + " | " +
          " | ".join(f"speed-up ({t})" for t in transfers) + " | halo MB/GPU/step | halo/interior work |")
    print("|" + "---|" * (6 + 3 * len(transfers)))
    base = None
    for p in gpus:
        rows = [step_ms(w, h, p, t_cell, t) for t in transfers]
        r = rows[0]
        mem_gb = r["mem"] / 1e9
        if mem_gb > GPU_MEMORY * 0.85 / 1e9:
            print(f"| {p} | {r['block']} | {mem_gb:.0f} | does not fit in 80 GB |" + " |" * (3 * len(transfers) + 2))
            continue
        if base is None:
            base = (p, [x["total"] for x in rows])
        px, py, bw, bh = split(w, h, p)
        ratio = ((bw + 2 * HALO) * (bh + 2 * HALO) / (bw * bh) - 1) if p > 1 else 0
        speed = [base[1][k] * base[0] / x["total"] for k, x in enumerate(rows)]
        print(f"| {p} | {r['block']} | {mem_gb:.1f} | {r['compute']:.3g} | " +
              " | ".join(f"{x['exchange']:.3g}" for x in rows) + f" | {r['reduce']:.2g} | " +
              " | ".join(f"{x['total']:.3g}" for x in rows) + " | " +
              " | ".join(f"{s:.3g}" for s in speed) + f" | {r['halo_bytes'] / 1e6:.2f} | {ratio:.3f} |")


def weak(title, block, gpus, t_cell, transfers):
    print(f"\n### {title}\n")
    print("| GPUs | region | " + " | ".join(f"step ms ({t})" for t in transfers) + " | " +
          " | ".join(f"efficiency ({t})" for t in transfers) + " |")
    print("|" + "---|" * (2 + 2 * len(transfers)))
    one = block * block * t_cell * 1e3
    for p in gpus:
        px, py, _, _ = split(block * p, block, p)  # a row of blocks is the worst case; take a square-ish grid
        side = int(math.sqrt(p))
        while p % side:
            side -= 1
        w, h = block * (p // side), block * side
        rows = [step_ms(w, h, p, t_cell, t) for t in transfers]
        print(f"| {p} | {w} x {h} | " + " | ".join(f"{x['total']:.3g}" for x in rows) + " | " +
              " | ".join(f"{one / x['total']:.2f}" for x in rows) + " |")


def main():
    seed_t = SEED_MS_8192x4096 * 1e-3 / (8192 * 4096)
    floor_t = BYTES_PER_CELL_STEP / (HBM_BPS * HBM_EFFICIENCY)
    print(f"t_cell: seed {seed_t * 1e9:.2f} ns, memory-bound kernels {floor_t * 1e9:.3f} ns")
    gpus = [1, 8, 64, 512]
    transfers = ["rows", "packed", "direct"]
    table("Strong scaling, 8192 x 4096 Grand Canyon, the seed's kernels (100 ms per step on one GPU)",
          8192, 4096, gpus, seed_t, transfers)
    table("Strong scaling, 8192 x 4096, memory-bound kernels (344 B/cell at 70% of 3.35 TB/s)",
          8192, 4096, gpus, floor_t, transfers)
    table("Strong scaling, 100,000 x 100,000 basin, memory-bound kernels", 100000, 100000, gpus, floor_t, transfers)
    table("Strong scaling, 100,000 x 100,000 basin, the seed's kernels", 100000, 100000, gpus, seed_t, transfers)
    weak("Weak scaling, 4096 x 4096 per GPU, memory-bound kernels", 4096, gpus, floor_t, transfers)
    weak("Weak scaling, 4096 x 4096 per GPU, the seed's kernels", 4096, gpus, seed_t, transfers)


if __name__ == "__main__":
    main()
