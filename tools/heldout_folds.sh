#!/usr/bin/env bash
# Held-out-view error of the visual hull and of its refinement, over k folds (SPEC §8).
#
#   bash tools/heldout_folds.sh SCENE OUT [--folds K] [--dilate PX] [--threshold T] [-- REFINE OPTIONS...]
#
# Fold f holds out views f, f+K, f+2K, ... (spread around the rig). For each fold the hull is
# carved WITHOUT the held-out views, refined without them, and both meshes are scored on them:
# neither the hull, the refinement nor the colouring ever sees a held-out photograph. Prints one
# line per fold and the mean over the folds; everything is kept under OUT/fold_F/, and
# OUT/folds.json holds every fold's `mvflow heldout` summaries (per view and pooled) for the hull
# and the refined mesh, and the means. The hull is `mvflow hull`'s default (no dilation) unless
# --dilate says otherwise.
#
# A PSNR is +inf where the error is zero, and an error with no scored pixel is NaN: `mvflow
# heldout` prints them as inf and nan and writes null in its JSON, and so does this script for a
# mean over folds that holds one (inf if any fold's is inf, nan if any is nan).
set -euo pipefail
mvflow=${MVFLOW:-$(cd "$(dirname "$0")/.." && pwd)/build/tools/mvflow}  # MVFLOW: another build
[ -x "$mvflow" ] || { echo "$0: $mvflow is missing: build first (bash tools/build.sh)" >&2; exit 1; }

[ $# -ge 2 ] || { echo "usage: $0 SCENE OUT [--folds K] [--dilate PX] [--threshold T] [-- REFINE OPTIONS...]" >&2; exit 2; }
scene=$1 out=$2
shift 2
folds=4 dilate=0 threshold=0.19
while [ $# -gt 0 ]; do
  case $1 in
    --folds) folds=$2; shift 2 ;;
    --dilate) dilate=$2; shift 2 ;;
    --threshold) threshold=$2; shift 2 ;;
    --) shift; break ;;
    *) echo "$0: unknown option $1" >&2; exit 2 ;;
  esac
done
refine_options=("$@")

# Runs a step, its output in LOG; on failure says which and shows the log's end.
step() {
  local log=$1
  shift
  "$@" > "$log" 2>&1 || { echo "$0: failed: $* (log: $log)" >&2; tail -5 "$log" >&2; exit 1; }
}

# "MAE PSNR silhouette" of the pooled line of `mvflow heldout`.
score() {
  step "$3.log" "$mvflow" heldout "$scene" "$1" --views "$2" --threshold "$threshold" --json "$3"
  awk '$1 == "all" { print $2, $3, $4 }' "$3.log"
}

mkdir -p "$out"
rm -f "$out/scores.tmp" "$out/folds.tmp"
step "$out/scene.log" "$mvflow" info "$scene" --json "$out/scene.json"
views=$(grep -m1 -o '"count": *[0-9]*' "$out/scene.json" | grep -o '[0-9]*$')
[[ $folds =~ ^[0-9]+$ ]] && folds=$((10#$folds)) && [ "$folds" -ge 2 ] && [ "$folds" -le "$views" ] ||
  { echo "$0: --folds must be a whole number from 2 to the scene's $views views (got '$folds')" >&2; exit 2; }

printf '%-5s %-12s %28s %28s %s\n' fold views "hull: MAE PSNR silhouette" "refined: MAE PSNR silhouette" \
  "refined vertices, Σg/vertex before → after, seconds"
for ((f = 0; f < folds; ++f)); do
  held=$(seq -s, "$f" "$folds" $((views - 1)))
  dir=$out/fold_$f
  mkdir -p "$dir"
  step "$dir/hull.log" "$mvflow" hull "$scene" -o "$dir/hull.ply" --threshold "$threshold" --dilate "$dilate" \
    --exclude-views "$held"
  start=$(date +%s%N)
  step "$dir/refine.log" "$mvflow" refine "$scene" --mesh "$dir/hull.ply" --exclude-views "$held" \
    -o "$dir/refined.ply" --report "$dir/report.json" "${refine_options[@]}"
  seconds=$(awk -v a="$start" -v b="$(date +%s%N)" 'BEGIN { print (b - a) / 1e9 }')
  hull_score=$(score "$dir/hull.ply" "$held" "$dir/hull_heldout.json")
  refined_score=$(score "$dir/refined.ply" "$held" "$dir/refined_heldout.json")
  vertices=$(grep -o '→ [0-9]* vertices' "$dir/refine.log" | grep -o '[0-9]*' || true)
  g=$(grep '^Σg/vertex' "$dir/refine.log" | sed 's/Σg\/vertex *//' || true)
  printf '%-5s %-12s %28s %28s %s, %s, %.1f s\n' "$f" "$held" "$hull_score" "$refined_score" "$vertices" "$g" "$seconds"
  echo "$hull_score $refined_score" >> "$out/scores.tmp"
  {
    [ "$f" -gt 0 ] && echo ","
    printf '{"fold": %d, "held_out_views": [%s], "refined_vertices": %s, "refine_seconds": %s,\n"hull": ' \
      "$f" "$held" "${vertices:-0}" "$seconds"
    cat "$dir/hull_heldout.json"
    printf ',\n"refined": '
    cat "$dir/refined_heldout.json"
    printf '}'
  } >> "$out/folds.tmp"
done
mv "$out/scores.tmp" "$out/scores.txt"
# The means of the six columns and the MAE change; a column with a value that is no finite number
# (inf, nan as `mvflow heldout` prints them) has the mean inf or nan, as does a change from them or
# from a zero MAE. A fold counts as worse only when both MAEs are numbers.
means=$(awk 'function finite(x) { return x ~ /^[-+]?([0-9]+[.]?[0-9]*|[.][0-9]+)([eE][-+]?[0-9]+)?$/ }
  { for (i = 1; i <= 6; ++i) if (finite($i)) s[i] += $i; else if (tolower($i) ~ /nan/) nan[i] = 1; else inf[i] = 1
    if (finite($1) && finite($4) && $4 > $1) worse++ }
  END {
    split("%.6f %.4f %.6f %.6f %.4f %.6f", format, " ")
    for (i = 1; i <= 6; ++i) printf "%s ", (nan[i] ? "nan" : inf[i] ? "inf" : sprintf(format[i], s[i] / NR))
    printf "%s %d", (nan[1] || inf[1] || nan[4] || inf[4] || s[1] == 0 ? "nan" : sprintf("%.2f", 100 * (s[4] - s[1]) / s[1])),
           worse }' "$out/scores.txt")
read -r hm hp hs rm rp rs change worse <<< "$means"
# A JSON number, null for inf and nan (JSON has neither).
json_number() { if [[ $1 =~ ^-?[0-9] ]]; then printf '%s' "$1"; else printf null; fi; }
# A number with $1 decimals for the text, inf and nan as they are.
fixed() { if [[ $2 =~ ^-?[0-9] ]]; then printf "%.${1}f" "$2"; else printf '%s' "$2"; fi; }
# A JSON string: backslashes and quotes escaped.
json_string() { local text=${1//\\/\\\\}; printf '"%s"' "${text//\"/\\\"}"; }
{
  printf '{"scene": %s, "folds_count": %d, "hull_dilate": %d, "threshold": %s, "refine_options": %s,\n' \
    "$(json_string "$scene")" "$folds" "$dilate" "$(printf '%g' "$threshold")" "$(json_string "${refine_options[*]}")"
  printf '"mean": {"hull": {"mae": %s, "psnr_db": %s, "silhouette_disagreement": %s},\n' \
    "$(json_number "$hm")" "$(json_number "$hp")" "$(json_number "$hs")"
  printf '  "refined": {"mae": %s, "psnr_db": %s, "silhouette_disagreement": %s},\n' \
    "$(json_number "$rm")" "$(json_number "$rp")" "$(json_number "$rs")"
  printf '  "mae_change_percent": %s, "folds_refined_worse": %s},\n"folds": [\n' "$(json_number "$change")" "$worse"
  cat "$out/folds.tmp"
  printf ']}\n'
} > "$out/folds.json.tmp"
mv "$out/folds.json.tmp" "$out/folds.json"
rm -f "$out/folds.tmp"
printf "mean  %-12s %28s %28s\n" "" "$(fixed 4 "$hm") $(fixed 2 "$hp") $(fixed 4 "$hs")" \
  "$(fixed 4 "$rm") $(fixed 2 "$rp") $(fixed 4 "$rs")"
echo "refined vs hull: MAE ${change} %, worse in ${worse} of ${folds} folds (JSON: $out/folds.json)"
