#!/usr/bin/env bash
# Compile time per translation unit from a build's .ninja_log (the last build of each object):
# what each robot compiles (kernels.o: symoroc build of the robot's library, all its models'
# kernels, one after another; the units of its identification and diagnosis libraries), the
# slowest units overall, and the sum. Run after a clean build for comparable numbers
# (a warm rebuild lists only what it rebuilt, and -j2 under other load inflates every time):
#   cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release && ninja -C build -j2
#   bash bench/compile_times.sh build [top N]
set -euo pipefail
build=${1:-build}
top=${2:-15}
log="$build/.ninja_log"
[ -f "$log" ] || { echo "no $log: build first" >&2; exit 1; }
# ninja_log v5: start end mtime output hash; a later line for the same output replaces the earlier.
# Only objects of the current build graph (a deleted source's object stays in the log).
known=$(ninja -C "$build" -t targets all 2>/dev/null | awk -F': ' '$1 ~ /\.o$/ { print $1 }')
latest=$(awk 'NR == FNR { known[$1] = 1; next }
              FNR > 1 && ($4 in known) { t[$4] = ($2 - $1) / 1000 }
              END { for (o in t) printf "%.1f %s\n", t[o], o }' <(echo "$known") "$log" | sort -rn)
echo "## Each robot's units (symoro::<robot>_identification, _diagnosis: robot_units/<robot>/*)"
echo "$latest" | awk '$2 !~ /^\// && $2 ~ /robot_units\/[^\/]+\/([a-z_0-9]+\.cpp\.o|kernels\.o)$/ { n = split($2, p, "/"); printf "%8.1f s  %s/%s\n", $1, p[n-1], p[n] }' | sort -k3
echo
echo "## Per robot (sum)"
echo "$latest" | awk '$2 !~ /^\// && $2 ~ /robot_units\/[^\/]+\/([a-z_0-9]+\.cpp\.o|kernels\.o)$/ { n = split($2, p, "/"); s[p[n-1]] += $1; c[p[n-1]]++ } END { for (r in s) printf "%8.1f s  %s (%d units)\n", s[r], r, c[r] }' | sort -k3
echo
echo "## The $top slowest units"
echo "$latest" | head -n "$top" | awk '{ printf "%8.1f s  %s\n", $1, $2 }'
echo
echo "$latest" | awk '{ s += $1; if ($1 > 60) over++ } END { printf "sum %.0f s over %d units; %d over 60 s\n", s, NR, over }'
