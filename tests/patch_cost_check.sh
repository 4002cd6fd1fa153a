#!/usr/bin/env bash
# perf/patch_cost.sh on a small rendered scene: one line per scene with the three modes, each
# mode's seconds and iterations as the report gives them, the ratio to `off` and the sum; a build
# the CPU cannot run (or an unknown one) and a bad round count are refused.
#   tests/patch_cost_check.sh MVFLOW SOURCE_DIR WORK_DIR
set -euo pipefail
mvflow=$1 root=$2 work=$3
rm -rf "$work"
mkdir -p "$work"
"$mvflow" --log-level warn synth --amplitude 0 --views 8 --width 160 --height 120 --level 4 --init-vertices 300 \
  -o "$work/scene" > /dev/null
MVFLOW=$mvflow MVFLOW_KERNELS=baseline bash "$root/perf/patch_cost.sh" 1 "$work/scene" > "$work/out.txt"
python3 - "$work/out.txt" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
assert 'baseline: median seconds' in text, text
line = next(l for l in text.splitlines() if l.strip().startswith('scene '))
cells = re.findall(r'(off|oblique|on) ([\d.]+) s \((\d+)\) ([\d.]+)x', line)
assert [c[0] for c in cells] == ['off', 'oblique', 'on'], line
off = float(cells[0][1])
assert cells[0][3] == '1.00', line
for mode, seconds, iterations, ratio in cells:
    assert float(seconds) > 0 and int(iterations) >= 10, line
    # The seconds are printed to 1 ms, the ratio to 0.01, both from the unrounded medians.
    bound = 0.005 + float(ratio) * (0.0005 / float(seconds) + 0.0005 / off)
    assert abs(float(ratio) - float(seconds) / off) <= bound, line
total = next(l for l in text.splitlines() if l.strip().startswith('sum '))
assert re.search(r'off [\d.]+ s 1.00x', total), total
PY
if MVFLOW=$mvflow MVFLOW_KERNELS=bogus bash "$root/perf/patch_cost.sh" 1 "$work/scene" > /dev/null 2> "$work/err.txt"; then
  echo "an unknown build was not refused" >&2; exit 1
fi
grep -q 'failed' "$work/err.txt" || { cat "$work/err.txt" >&2; exit 1; }
status=0
bash "$root/perf/patch_cost.sh" 0 "$work/scene" > /dev/null 2>&1 || status=$?
[ "$status" -eq 2 ] || { echo "ROUNDS 0 gave exit $status, expected 2" >&2; exit 1; }
echo "patch_cost.sh: ok"
