#!/usr/bin/env bash
# The OpenMVS-sized case through the command line, image decoding included: `mvflow synth`
# renders a textured unit sphere (the bumpy sphere without bumps, mesh level 6) seen by 24 ring
# views of 640×480 with an initial mesh of 2 562 vertices pushed out to a mean radial error of
# 0.040; `mvflow refine` (default options) is timed as a whole; the mean radial error of the
# result is printed beside the peer's (OpenMVS RefineMesh, CPU, 2 threads: 37 s, 0.040 -> 0.0027).
#
#   perf/openmvs_case.sh [SCENE_DIR [REFINE OPTIONS...]]   (THREADS=2, MVFLOW=build/tools/mvflow by default)
#
# REFINE OPTIONS go to `mvflow refine`, e.g. `perf/openmvs_case.sh /tmp/case --max-iterations 30`.
set -euo pipefail
cd "$(dirname "$0")/.."
mvflow=${MVFLOW:-build/tools/mvflow}
threads=${THREADS:-2}
scene=${1:-/tmp/mvflow-openmvs-case}
refine_options=("${@:2}")

# offset 0.011547 × the sphere's box diagonal (2√3) = 0.040
[ -f "$scene/synth_par.txt" ] ||
  "$mvflow" --log-level warn synth --amplitude 0 --views 24 --width 640 --height 480 --level 6 \
    --init offset:0.011547 --init-vertices 2562 -o "$scene" >/dev/null

echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
start=$(date +%s.%N)
"$mvflow" --log-level warn refine "$scene" -o "$scene/refined.ply" --report "$scene/report.json" --threads "$threads" \
  "${refine_options[@]}"
end=$(date +%s.%N)
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"

python3 - "$scene" "$start" "$end" <<'EOF'
import json, math, struct, sys

def positions(path):
    data = open(path, 'rb').read()
    end = data.index(b'end_header\n') + len(b'end_header\n')
    header = data[:end].decode().split('\n')
    count = int(next(l for l in header if l.startswith('element vertex')).split()[2])
    sizes = {'char': 'b', 'uchar': 'B', 'short': 'h', 'ushort': 'H', 'int': 'i', 'uint': 'I', 'float': 'f', 'double': 'd'}
    element, properties = None, []
    for line in header:
        if line.startswith('element'):
            element = line.split()[1]
        elif line.startswith('property') and element == 'vertex':
            properties.append(line.split())
    layout = '<' + ''.join(sizes[p[1]] for p in properties)
    names = [p[2] for p in properties]
    step = struct.calcsize(layout)
    for i in range(count):
        values = struct.unpack_from(layout, data, end + i * step)
        yield values[names.index('x')], values[names.index('y')], values[names.index('z')]

def radial_error(path):
    errors = [abs(math.sqrt(x * x + y * y + z * z) - 1) for x, y, z in positions(path)]
    return len(errors), sum(errors) / len(errors)

scene, start, end = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
report = json.load(open(scene + '/report.json'))
v0, e0 = radial_error(scene + '/init.ply')
v1, e1 = radial_error(scene + '/refined.ply')
print(f'mvflow refine: {end - start:.2f} s wall (refinement alone {report["seconds"]:.2f} s), '
      f'{len(report["iterations"])} iterations, {report["status"]}')
print(f'vertices {v0} -> {v1}; mean radial error {e0:.4f} -> {e1:.4f}')
print(f'OpenMVS RefineMesh (CPU, 2 threads): 37 s, 2562 -> 7147 vertices, 0.040 -> 0.0027; '
      f'ratio {37 / (end - start):.1f}x')
EOF
