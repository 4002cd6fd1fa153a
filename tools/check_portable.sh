#!/usr/bin/env bash
# Opt-in check that the photo kernel's portable build compiles and gives the right g on arm64:
# cross-compiles tests/portable/kernel_check.cpp with the four engine sources it needs for aarch64
# (statically, so that qemu runs it without an arm64 sysroot), runs it under qemu, and compares
# its fingerprint with the same program built for this machine. With --all it also compiles
# every source of the configured build (build/compile_commands.json) with the aarch64 compiler
# (-fsyntax-only), for x86-only code outside the kernel.
# Needs Debian's g++-aarch64-linux-gnu and qemu-user-static (or qemu-user); not part of
# tools/setup.sh or tools/check.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
cross=${MVFLOW_CROSS_CXX:-aarch64-linux-gnu-g++}
qemu=$(command -v qemu-aarch64-static || command -v qemu-aarch64 || true)
if ! command -v "$cross" >/dev/null || [ -z "$qemu" ]; then
  echo "check_portable: needs $cross and qemu-aarch64: apt-get install g++-aarch64-linux-gnu qemu-user-static" >&2
  exit 2
fi
out=build-portable
mkdir -p "$out"
# The flags of the Release build (CMakeLists.txt), warnings as errors.
flags=(-std=c++20 -O3 -DNDEBUG -ffp-contract=off -Wall -Wextra -Wpedantic -Werror -I. -isystem /usr/include/eigen3)
sources=(tests/portable/kernel_check.cpp stages/flow/photo_kernel.cpp engine/model/camera.cpp engine/model/image.cpp
         engine/model/error.cpp)

echo "== $("$cross" --version | head -1)"
"$cross" "${flags[@]}" -static "${sources[@]}" -o "$out/kernel_check-aarch64"
file "$out/kernel_check-aarch64" | sed 's/, BuildID.*//'
echo "== $qemu $out/kernel_check-aarch64"
"$qemu" "$out/kernel_check-aarch64" | tee "$out/aarch64.txt"
# A build the CPU cannot run is refused with a message, not run.
if MVFLOW_KERNEL=avx2 "$qemu" "$out/kernel_check-aarch64" >/dev/null 2>"$out/refused.txt"; then
  echo "check_portable: MVFLOW_KERNEL=avx2 ran on aarch64" >&2
  exit 1
fi
echo "MVFLOW_KERNEL=avx2 on aarch64: $(cat "$out/refused.txt")"

echo "== $(c++ --version | head -1), this machine"
c++ "${flags[@]}" "${sources[@]}" -o "$out/kernel_check-native"
"$out/kernel_check-native" > "$out/native.txt" || { cat "$out/native.txt"; exit 1; }
grep -e '^kernel_check' -e 'fingerprint of the baseline' "$out/native.txt"
# Informational: the same bits need the same cameras, and Eigen's arm64 products fuse multiply-adds.
if [ "$(grep 'fingerprint of the baseline' "$out/native.txt")" = "$(grep 'fingerprint of the baseline' "$out/aarch64.txt")" ]; then
  echo "the baseline build gives the same bits on aarch64 as on this machine"
else
  echo "the baseline build's bits differ between aarch64 and this machine (both within the tolerance)"
fi

if [ "${1:-}" = "--all" ]; then
  [ -f build/compile_commands.json ] || { echo "check_portable: --all needs a configured build (tools/build.sh)" >&2; exit 2; }
  echo "== every source of build/compile_commands.json, $cross -fsyntax-only"
  python3 - "$cross" <<'EOF'
import json, shlex, subprocess, sys
from concurrent.futures import ThreadPoolExecutor
cross = sys.argv[1]
def check(entry):
    args = shlex.split(entry["command"])[1:]
    keep = [a for i, a in enumerate(args) if a not in ("-c", "-o") and (i == 0 or args[i - 1] != "-o")]
    run = subprocess.run([cross, "-fsyntax-only", *keep], cwd=entry["directory"], capture_output=True, text=True)
    return entry["file"], run.returncode, run.stderr
entries = json.load(open("build/compile_commands.json"))
failed = 0
with ThreadPoolExecutor(2) as pool:
    for path, code, errors in pool.map(check, entries):
        if code:
            failed += 1
            print("FAIL", path, *errors.splitlines()[:3], sep="\n  ")
print(f"{len(entries) - failed} compiled, {failed} failed for aarch64")
sys.exit(1 if failed else 0)
EOF
fi
