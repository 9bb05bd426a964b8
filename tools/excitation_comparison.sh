#!/usr/bin/env bash
# The comparison the paper leaves open (issue 29, docs/excitation.md): CRANE-X7's structured
# aggregate AG02 against an optimized (D-optimal) Fourier trajectory OF01 of the same length
# (10 periods of 11.28 s, from rest at posture A, under AG02's fastest speed level), both on the
# digital twin with realistic effects (build/excitation/effects.yaml), TRIALS noise seeds each,
# each trial identified on its own at 10 ms (OLS, PD audit, SDP, CLIE, rescue onto the
# physically consistent set, validation on the held-out V01-V03). The table:
# build/excitation/comparison.md. Needs a build (tools/run_main.sh or ninja -C build dynid)
# and the main study's accepted parameters (build/study, tools/run_main.sh) as the nominal model
# of the torque limits. Resumable: finished steps are skipped.
set -euo pipefail
cd "$(dirname "$0")/.."
dynid=build/runtime/tools/dynid
out=build/excitation
trials=${TRIALS:-5}
mkdir -p $out
if [ ! -f $out/design/trajectories.yaml ]; then
  $dynid excite --robot crane_x7 -o $out/design --from-design robots/crane_x7/trajectories.yaml \
    --params build/study/report/parameters.yaml --optimized 1 --period 11.28 --periods 10 | tee $out/excite.txt
fi
cat > $out/effects.yaml <<'YAML'
# The comparison's realistic effects, on top of twin.yaml's defaults (encoder and current noise,
# timestamp jitter, dropped reads; the servos' quantization is always on): 0.25 deg of play
# (e-manual) in the gears of joints 1 and 4 and a 2 ms actuation delay. Play on every joint at
# once makes the 1 kHz FF+PD loop limit-cycle at the current limit (docs/excitation.md).
effects:
  backlash: {enabled: true, width: [0.25 deg, 0, 0, 0.25 deg, 0, 0, 0, 0]}
  actuation_delay: {enabled: true}
YAML
$dynid twin dataset --robot crane_x7 --design $out/design/trajectories.yaml --only AG02 OF01 V01 V02 V03 \
  --trials "$trials" --seed 7 --config $out/effects.yaml -o $out/data
for k in $(seq 1 "$trials"); do
  for t in AG02 OF01; do
    study=$out/study-$t-t$k
    [ -f $out/identify-$t-t$k.txt ] && [ -f $study/report/parameters.yaml ] && continue
    $dynid identify --robot crane_x7 --design $out/design/trajectories.yaml --data $out/data --trial "$k" --only $t \
      --interval 10 --consistency physical -o $study > $out/identify-$t-t$k.txt 2>&1
  done
done
python3 tools/excitation_table.py $out "$trials" | tee $out/comparison.md
