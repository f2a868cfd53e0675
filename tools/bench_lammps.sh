#!/usr/bin/env bash
# Side-by-side throughput: our DEM engine (tests/dem/bench_dem_packing) against LAMMPS
# pair_style granular on the SAME scene: the same particles, bit for bit (positions and
# velocities are regenerated here with the bench's std::mt19937_64(1) draws), the same
# material, time step, skin and step count. See docs/dem_vs_lammps.md.
#
#   tools/bench_lammps.sh [rounds [steps]]     (default 3 rounds, 300 steps)
#
# Env: BENCH   our bench binary   (default build/bench/bench_dem_packing)
#      LMP     LAMMPS binary      (default: lmp, lmp_serial or lmp_stable on PATH)
#      WORK    scratch directory  (default: a fresh mktemp -d, removed at the end)
#      MPI2=1  also run LAMMPS on 2 MPI ranks (the Debian package has no OPENMP package)
#      BENCH_BASE  a second bench binary (e.g. an older build), run in every round too: its
#              rows say "magbrush base", and "new/base" gives the same-round ratio of the two
# The two codes run alternately, back to back, `rounds` times; the table gives the median
# and the min–max of each rate and of the per-round ratio ours/LAMMPS.
set -euo pipefail

ROUNDS=${1:-3}
STEPS=${2:-300}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BENCH=${BENCH:-$ROOT/build/bench/bench_dem_packing}
PY=/usr/bin/python3

# ---- LAMMPS ------------------------------------------------------------------------------
find_lmp() {
  if [[ -n "${LMP:-}" ]]; then command -v "$LMP" && return; fi
  for c in lmp lmp_serial lmp_stable lmp_mpi; do command -v "$c" && return; done
  return 1
}
if ! LMP_BIN=$(find_lmp); then
  if [[ $(id -u) -ne 0 ]]; then
    echo "LAMMPS not found and not root: install it with 'sudo apt-get install -y lammps'" \
         "(Debian/Ubuntu; needs the GRANULAR package) or set LMP=/path/to/lmp" >&2
    exit 1
  fi
  echo "installing LAMMPS (apt-get install -y lammps) ..." >&2
  DEBIAN_FRONTEND=noninteractive apt-get install -y lammps >&2 ||
    { apt-get update >&2 && DEBIAN_FRONTEND=noninteractive apt-get install -y lammps >&2; }
  LMP_BIN=$(find_lmp) || { echo "apt-get installed lammps but no lmp binary found" >&2; exit 1; }
fi
LMP_HELP=$("$LMP_BIN" -h)
grep -q GRANULAR <<<"$LMP_HELP" || { echo "$LMP_BIN lacks the GRANULAR package" >&2; exit 1; }
LMP_VERSION=$(sed -n 's/^Large-scale Atomic\/Molecular Massively Parallel Simulator - //p' <<<"$LMP_HELP")
grep -q OPENMP <<<"$LMP_HELP" && echo "note: this LAMMPS has OPENMP; the script still compares serial (and MPI2=1)" >&2
[[ -x "$BENCH" ]] || { echo "no bench binary at $BENCH (build target bench_dem_packing)" >&2; exit 1; }
[[ -z "${BENCH_BASE:-}" || -x "$BENCH_BASE" ]] || { echo "no bench binary at BENCH_BASE=$BENCH_BASE" >&2; exit 1; }

if [[ -n "${WORK:-}" ]]; then mkdir -p "$WORK"; else WORK=$(mktemp -d); trap 'rm -rf "$WORK"' EXIT; fi
cd "$WORK"

# ---- scene: data files + parameters (python3 + numpy) --------------------------------------
# Writes packing_<n>.data (n = 24, 38 per side) and params.sh, prints the scene check.
"$PY" - <<'EOF'
import math
import numpy as np

# std::mt19937_64 + std::uniform_real_distribution<double>(-1, 1) as in libstdc++
class MT64:
    def __init__(self, seed):
        M = (1 << 64) - 1
        self.mt = [seed & M]
        for i in range(1, 312):
            p = self.mt[-1]
            self.mt.append((6364136223846793005 * (p ^ (p >> 62)) + i) & M)
        self.i = 312
    def twist(self):
        mt, M = self.mt, (1 << 64) - 1
        for k in range(312):
            y = (mt[k] & 0xFFFFFFFF80000000) | (mt[(k + 1) % 312] & 0x7FFFFFFF)
            v = mt[(k + 156) % 312] ^ (y >> 1)
            if y & 1:
                v ^= 0xB5026F5AA96619E9
            mt[k] = v
        self.i = 0
    def __call__(self):
        if self.i >= 312:
            self.twist()
        x = self.mt[self.i]; self.i += 1
        x ^= (x >> 29) & 0x5555555555555555
        x ^= (x << 17) & 0x71D67FFFEDA60000
        x ^= (x << 37) & 0xFFF7EEE000000000
        x ^= x >> 43
        return x & ((1 << 64) - 1)
    def uniform(self):  # generate_canonical<double, 53> with a 64-bit engine, then a + (b-a) u
        u = float(self()) / 18446744073709551616.0
        if u >= 1.0:
            u = math.nextafter(1.0, 0.0)
        return 2.0 * u - 1.0

assert abs(MT64(1).uniform() - -0.73224671197493452) < 1e-16  # first draw of the C++ engine

d, rho, E, nu, mu, alpha, polygon = 60e-6, 2200.0, 1e9, 0.35, 0.45, 0.6, 12
r = 0.5 * d
spacing = 0.995 * d
m = rho * 4.0 / 3.0 * math.pi * r**3
# time step: dem/time_step.cpp (automatic: 0.2 x min(Rayleigh, Hertz t_c/10 at 1 m/s))
G = E / (2 * (1 + nu))
rayleigh = math.pi * r * math.sqrt(rho / G) / (0.1631 * nu + 0.8766)
Estar = 1.0 / (2 * (1 - nu * nu) / E)
Gstar = 1.0 / (2 * (2 - nu) / G)
mstar, Rstar = m / 2, r / 2
hertz = 2.868 * (mstar**2 / (Rstar * Estar**2 * 1.0)) ** 0.2 / 10
dt = 0.2 * min(rayleigh, hertz)
# LAMMPS 'damping tsuji' turns its coefficient e into alpha by Tsuji's polynomial; invert it
# so that LAMMPS's normal dashpot alpha sqrt(m* k_n) delta^1/4 equals ours (alpha = 0.6).
poly = lambda e: (1.2728 - 4.2783*e + 11.087*e**2 - 22.348*e**3 + 27.467*e**4
                  - 18.022*e**5 + 4.8218*e**6)
lo, hi = 0.01, 0.99
for _ in range(200):
    mid = 0.5 * (lo + hi)
    lo, hi = (mid, hi) if poly(mid) > alpha else (lo, mid)
e_tsuji = 0.5 * (lo + hi)
# LAMMPS damps the tangential force with x_gamma_t * eta_n; ours with alpha sqrt(m* k_t):
# x_gamma_t = sqrt(k_t / k_n) = sqrt(8 G* / (4/3 E*)) makes them equal.
xgt = math.sqrt(8 * Gstar / (4.0 / 3.0 * Estar))
# ours: rolling torque r mu_r F_n, mu_r = sin(pi/n); LAMMPS rolling sds: R_eff mu_roll F_n
mu_r = math.sin(math.pi / polygon)
mu_roll = mu_r * r / Rstar
# rolling spring of the sds model (ours has none): ~ the tangential stiffness at the mean overlap
delta0 = d - spacing
k_roll = 8 * Gstar * math.sqrt(Rstar * delta0)

with open("params.sh", "w") as f:
    for k, v in dict(DT=dt, E_TSUJI=e_tsuji, XGT=xgt, MU_ROLL=mu_roll, K_ROLL=k_roll,
                     SKIN=0.1 * d, MU=mu, E_MOD=E, NU=nu).items():
        f.write(f"{k}={v:.10g}\n")

for n in (24, 38):
    N = n**3
    g = MT64(1)  # the bench builds each size from a fresh engine
    pos = np.empty((n, n, n, 3)); vel = np.empty((n, n, n, 3))
    for i in range(n):
        for j in range(n):
            for k in range(n):
                pos[i, j, k] = [(i + 0.5) * spacing + 0.2e-6 * g.uniform(),
                                (j + 0.5) * spacing + 0.2e-6 * g.uniform(),
                                (k + 0.5) * spacing + 0.2e-6 * g.uniform()]
                vel[i, j, k] = [0.05 * g.uniform(), 0.05 * g.uniform(), 0.05 * g.uniform()]
    L = n * spacing
    # initial contacts / overlaps: only the 6 lattice neighbours can touch (next: 1.41 d)
    olap = []
    for ax in range(3):
        dx = np.roll(pos, -1, axis=ax) - pos
        dx -= L * np.round(dx / L)
        dist = np.linalg.norm(dx, axis=-1)
        olap.append(d - dist)
    olap = np.concatenate([o.ravel() for o in olap])
    touch = olap > 0
    print(f"scene N={N}: box {L*1e6:.3f} um, dt = {dt:.6g} s, initial contacts/particle "
          f"{2*touch.sum()/N:.4f}, mean overlap {olap[touch].mean()*1e6:.4f} um "
          f"(min {olap.min()*1e6:.3f}, max {olap.max()*1e6:.3f})")
    ids = np.arange(1, N + 1)
    p = pos.reshape(-1, 3); v = vel.reshape(-1, 3)
    with open(f"packing_{n}.data", "w") as f:
        f.write(f"bench_dem_packing scene, {n}^3 spheres\n\n{N} atoms\n1 atom types\n\n")
        f.write(f"0 {L!r} xlo xhi\n0 {L!r} ylo yhi\n0 {L!r} zlo zhi\n\nAtoms # sphere\n\n")
        for t in range(N):  # atom-ID type diameter density x y z
            f.write(f"{ids[t]} 1 {d!r} {rho!r} {p[t,0]!r} {p[t,1]!r} {p[t,2]!r}\n")
        f.write("\nVelocities\n\n")
        for t in range(N):
            f.write(f"{ids[t]} {v[t,0]!r} {v[t,1]!r} {v[t,2]!r} 0 0 0\n")
    np.save(f"olap0_{n}.npy", olap)
print(f"dt {dt:.6g} s; tsuji e {e_tsuji:.6f}; x_gamma_t {xgt:.6f}; mu_roll {mu_roll:.6f}; "
      f"k_roll {k_roll:.6g} N/m")
EOF
# shellcheck disable=SC1091
source params.sh

cat > in.packing <<EOF
# bench_dem_packing scene in LAMMPS (written by tools/bench_lammps.sh)
units           si
atom_style      sphere
boundary        p p p
comm_modify     vel yes
newton          on
read_data       \${data}
neighbor        ${SKIN} bin
neigh_modify    delay 0 every 1 check yes
pair_style      granular
pair_coeff      * * hertz/material ${E_MOD} ${E_TSUJI} ${NU} damping tsuji tangential mindlin NULL ${XGT} ${MU} rolling sds ${K_ROLL} 0.0 ${MU_ROLL} limit_damping
timestep        ${DT}
fix             integ all nve/sphere
compute         nc all contact/atom
compute         ncsum all reduce sum c_nc
variable        cpp equal c_ncsum/atoms
thermo_style    custom step atoms ke v_cpp
thermo          100000
run             20
run             \${steps}
print           "CONTACTS_PER_PARTICLE \${cpp}"
write_dump      all custom final.dump id x y z radius modify sort id
EOF

run_lammps() { # n nproc -> rate, prints loop time
  local n=$1 np=$2 log=lmp_${1}_${2}.log
  if [[ $np -eq 1 ]]; then
    OMP_NUM_THREADS=1 "$LMP_BIN" -nocite -in in.packing -var data "packing_$n.data" -var steps "$STEPS" -log none -screen "$log" >/dev/null
  else
    OMP_NUM_THREADS=1 mpirun --allow-run-as-root --oversubscribe -np "$np" "$LMP_BIN" -nocite -in in.packing \
      -var data "packing_$n.data" -var steps "$STEPS" -log none -screen "$log" >/dev/null 2>&1
  fi
  # the second 'Loop time' is the timed run (the first is the 20-step warm-up)
  local loop
  loop=$(grep '^Loop time' "$log" | tail -1 | awk '{print $4}')
  "$PY" -c "print('%.4g' % ($STEPS * $n**3 / $loop))"
}

echo "LAMMPS: $LMP_BIN ($LMP_VERSION); ours: $BENCH${BENCH_BASE:+ (base: $BENCH_BASE)}; $ROUNDS rounds of $STEPS steps"
: > results.txt
: > loads.txt
for ((round = 1; round <= ROUNDS; ++round)); do
  # ours: both sizes, 1 and 2 threads in one process; rate and out% (HDF5 snapshot every 100 steps)
  OMP_NUM_THREADS=1 "$BENCH" "$STEPS" 2 > ours_$round.txt
  awk -v r="$round" '$1 ~ /^[0-9]+$/ && NF > 10 {print r, "ours", $1, $2, $3, $9, $12}' ours_$round.txt >> results.txt
  if [[ -n "${BENCH_BASE:-}" ]]; then
    OMP_NUM_THREADS=1 "$BENCH_BASE" "$STEPS" 2 > base_$round.txt
    awk -v r="$round" '$1 ~ /^[0-9]+$/ && NF > 10 {print r, "base", $1, $2, $3, $9, $12}' base_$round.txt >> results.txt
  fi
  for n in 24 38; do
    echo "$round lammps $((n*n*n)) 1 $(run_lammps $n 1) 0 -" >> results.txt
    if [[ "${MPI2:-0}" == 1 ]]; then
      echo "$round lammps $((n*n*n)) 2 $(run_lammps $n 2) 0 -" >> results.txt
    fi
  done
  echo "round $round: load average $(cut -d' ' -f1-3 /proc/loadavg)" | tee -a loads.txt >&2
done

# ---- table ---------------------------------------------------------------------------------
"$PY" - "$STEPS" <<'EOF'
import sys, glob, numpy as np
steps = int(sys.argv[1])
rows = [l.split() for l in open("results.txt")]
import collections
rate = collections.defaultdict(list); out = {}
for rnd, code, N, th, r, outp, cont in rows:
    rate[(int(N), code, int(th))].append(float(r))
    if code in ("ours", "base"):
        out.setdefault((code, int(N), int(th)), []).append(float(outp))
        out.setdefault(("cont", code, int(N)), []).append(float(cont))
def stat(v):
    v = sorted(v); return np.median(v), v[0], v[-1]
print()
print(f"{'N':>7} {'code':>16} {'thr':>4} {'p-steps/s median':>17} {'(min-max)':>21}  {'ours/LAMMPS median (min-max)':>32}")
for N in sorted({k[0] for k in rate}):
    lam = rate.get((N, "lammps", 1))
    for (NN, code, th) in sorted(k for k in rate if k[0] == N):
        med, lo, hi = stat(rate[(NN, code, th)])
        name = {"ours": "magbrush", "base": "magbrush base"}.get(code, "LAMMPS serial" if th == 1 else "LAMMPS MPI x2")
        ratio = ""
        if code in ("ours", "base") and lam:
            ref = rate.get((N, "lammps", th), lam)  # LAMMPS on as many ranks if measured
            rr = [a / b for a, b in zip(rate[(NN, code, th)], ref)]  # same round
            m, a, b = stat(rr)
            best = max(rate[(NN, code, th)]) / max(ref)
            ratio = (f"{m:6.2f} ({a:.2f}-{b:.2f}) best/best {best:.2f} "
                     f"vs {'MPI x2' if ref is not lam else 'serial'}")
            o = np.median(out[(code, N, th)])
            ratio += f"   [out {o:.1f}% of ours]"
        print(f"{N:7d} {name:>16} {th:4d} {med:17.4g} {f'({lo:.3g}-{hi:.3g})':>21}  {ratio}")
base = sorted(k for k in rate if k[1] == "base")
if base:
    print("\nnew/base (per-round rate of BENCH / BENCH_BASE in the same round): median (min-max)")
    for (N, _, th) in base:
        rr = [a / b for a, b in zip(rate[(N, "ours", th)], rate[(N, "base", th)])]
        m, a, b = stat(rr)
        print(f"{N:7d} {th:4d} threads  {m:.3f} ({a:.3f}-{b:.3f})")
print("\n(ratio = per-round rate of ours / LAMMPS in the same round, same number of threads/ranks if")
print(" measured; best/best = fastest round of each, the least disturbed by other load. Ours includes")
print(" one HDF5 snapshot per 100 steps (out%), LAMMPS writes nothing in the timed loop)")
print("raw (round code N threads p-steps/s out% contacts):")
for row in rows:
    print("  " + " ".join(row))
print("machine load (1, 5, 15 min) after each round:")
for l in open("loads.txt"):
    print("  " + l.strip())
EOF

# contacts and overlaps: LAMMPS (compute contact/atom at the end, overlaps from its final
# positions) and ours (the bench's 'contacts' column at the end; initial overlaps are the same
# by construction since the positions are the same)
echo
for n in 24 38; do
  N=$((n*n*n))
  lmp_c=$(grep '^CONTACTS_PER_PARTICLE' lmp_${n}_1.log | awk '{print $2}')
  ours_c=$(awk -v N=$N '$1 == N && $2 == 1 {print $12}' ours_$ROUNDS.txt)
  "$PY" - "$n" "$lmp_c" "$ours_c" <<'EOF'
import sys, numpy as np
n, lc, oc = int(sys.argv[1]), float(sys.argv[2]), sys.argv[3]
print(f"N={n**3}: contacts/particle LAMMPS {lc:.4f} (compute contact/atom, end of run), ours {oc} (end of run); "
      f"initial mean overlap {np.load(f'olap0_{n}.npy')[np.load(f'olap0_{n}.npy') > 0].mean()*1e6:.4f} um (both)")
EOF
done
# LAMMPS final positions -> mean overlap (the last LAMMPS run was N=38^3)
"$PY" - <<'EOF'
import numpy as np
a = np.loadtxt("final.dump", skiprows=9)
N = len(a); n = round(N ** (1 / 3))
box = [float(x) for x in open("final.dump").read().split("ITEM: BOX BOUNDS")[1].split("\n")[1].split()]
L = box[1] - box[0]
pos = a[:, 1:4].reshape(n, n, n, 3)
d = 2 * a[0, 4]
ol = []
for ax in range(3):
    dx = np.roll(pos, -1, axis=ax) - pos
    dx -= L * np.round(dx / L)
    ol.append((d - np.linalg.norm(dx, axis=-1)).ravel())
ol = np.concatenate(ol)
print(f"N={N}: LAMMPS end of run: {2*(ol > 0).sum()/N:.4f} lattice contacts/particle, mean overlap {ol[ol > 0].mean()*1e6:.4f} um")
EOF
