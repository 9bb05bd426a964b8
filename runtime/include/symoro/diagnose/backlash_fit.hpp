// Backlash from the closed loop's high band. Play in a gear lets the rotor float between the
// flanks wherever the mesh torque is small; the 1 kHz FF+PD loop then chatters, and the measured
// torque (current) gains power far above the diagnosis's 5 Hz band, where the stack's columns
// cannot see it (a linear column of the low band explains < 2 % of it). So backlash is judged
// by simulating the experiment: the robot's digital twin (its nominal description, plus the
// effects the diagnosis already selected) runs the fitting run's references in closed loop.
// A real arm's high band also holds what the twin does not model (current noise, the current
// loop, its encoders' noise): judged against the twin alone, any real arm has play. So the null
// is the twin with the log's own floor (high_band.hpp: the encoder noise estimated from the log
// put into the twin, and the torque the controller's law does not explain added to it):
//   1. a joint whose measured high-band torque rms exceeds the null's by more than the
//      simulation's own spread across noise seeds (and by a relative margin) has a candidate;
//   2. the joint with the largest excess gets the play width whose null reproduces its measured
//      high-band rms (bisection: the chatter grows with the width), and the others are
//      re-judged with it in the simulation (a neighbour's chatter couples into them);
//   3. until no joint exceeds.
// A joint whose mesh torque never reverses (a gravity-loaded elbow) never crosses its play: its
// backlash leaves no trace in either band and is not named. The width is the twin's mesh's: an
// arm whose gears are stiffer or better damped chatters less for the same play.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/diagnose/high_band.hpp"
#include "symoro/diagnose/selection.hpp"
#include "symoro/io/log.hpp"
#include "symoro/robot/model_handle.hpp"
#include "symoro/trajectory/sampled_reference.hpp"
#include "symoro/twin/config.hpp"

namespace symoro::diagnose {

struct BacklashFinding {
  int joint = 0;                // 1-based
  double width = 0;             // rad, total play
  double measured = 0;          // N m, high-band torque rms of the data
  double simulated_before = 0;  // N m, of the simulation without this joint's play (mean over seeds)
  double spread = 0;            // N m, its standard deviation over seeds
  double simulated_after = 0;   // N m, with the fitted play
};

struct BacklashFit {
  Eigen::VectorXd measured, simulated, spread;  // per joint, the final judgement (N m); simulated: the null
  LoopFloor floor;                              // the log's own floor, in the null
  std::vector<BacklashFinding> findings;
  double delay = 0;  // s, the refined actuation delay (0: none was selected)
  int simulations = 0;
  std::vector<std::string> notes;  // joints the twin cannot give play (said in the report)
};

// The twin description with the effects the selection named that the twin can play: Coulomb
// friction, offsets (the twin's is the external torque: minus the effect) and the delay.
twin::TwinConfig with_selected_effects(twin::TwinConfig c, const Selection& s);

// `full`: the robot's full model (the twin's plant); `nominal`: the robot's twin configuration
// with the effects already diagnosed switched on and every unknown one off (backlash off);
// `measured` the fitting run and `reference` its reference at every cycle (the log's own
// references: the motion that was logged).
BacklashFit fit_backlash(const robot::ModelHandle& full, const io::Log& measured,
                         const trajectory::SampledReference& reference, twin::TwinConfig nominal,
                         const BacklashFitOptions& options = {});

}  // namespace symoro::diagnose
