// dynid excite: identification trajectories for any robot from its robots/ folder alone: the
// paper's structured families (trajectory/structured_design.hpp) or a given design file, and
// optimized Fourier series (excitation/design.hpp) under the same speed limits, in one
// design file that dynid twin, control, trajectories and identify read (--design), with the
// excitation quality of every trajectory side by side.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "dynid_excite_choice.hpp"
#include "dynid_excite_payload.hpp"
#include "dynid_identify.hpp"
#include "dynid_robots.hpp"
#include "dynid_numbers.hpp"
#include "dynid_trajectories.hpp"
#include "symoro/excitation/design.hpp"
#include "symoro/excitation/quality.hpp"
#include "symoro/io/atomic_file.hpp"
#include "symoro/io/parameters_yaml.hpp"
#include "symoro/io/text_file.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/trajectory/structured_design.hpp"
#include "symoro/io/yaml_keys.hpp"

namespace symoro::dynid {

namespace {

namespace fs = std::filesystem;
constexpr double kDeg = 3.14159265358979323846 / 180.0;

struct ExciteOptions {
  std::string out;
  std::string model;        // "" robot.yaml's identified
  std::string from_design;  // structured families from this file instead of the generator
  std::string params;       // nominal phi; "" robot.yaml's nominal
  bool force = false;       // replace trajectories.yaml and quality.txt in -o
  int optimized = 3;
  int harmonics = excitation::ExcitationDesignOptions{}.harmonics;
  bool harmonics_given = false;
  double period = 0;         // s; 0: from the limits (auto_period), or chosen (excite_choice.hpp)
  double kappa_target = 0;   // > 0: choose the period for a scaled kappa below it
  double max_duration = 25;  // s, the longest optimized trajectory the choice may make
  int periods = 1;
  int starts = excitation::ExcitationDesignOptions{}.starts;
  std::uint64_t seed = excitation::ExcitationDesignOptions{}.seed;
  double torque_fraction = 0.8;
  double table = -1;                     // m below frame 0; < 0: none
  std::vector<std::string> half_spaces;  // "frame:nx,ny,nz:offset"
  double interval_ms = 10;
  std::vector<std::string> compare;  // logs of reference motions rated beside the design
  bool payload = false;              // one wrist motion D-optimal for a payload (PL01)
  int payload_joints = 3;
  PayloadExcitation wrist;  // with payload: which joints move, the parameter map
};

std::vector<double> numbers_of(const std::string& text, char sep, const std::string& what) {
  std::vector<double> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, sep)) {
    try {
      std::size_t used = 0;
      out.push_back(std::stod(item, &used));
      if (used != item.size() || !std::isfinite(out.back()) || std::abs(out.back()) > 1e6)
        throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw UsageError(fmt::format("{}: '{}' is not a finite number within 1e6", what, item));
    }
  }
  return out;
}

std::vector<excitation::HalfSpace> half_spaces(const ExciteOptions& options, const identify::ModelDescription& d) {
  const int frames = static_cast<int>(d.frames.size());
  std::vector<excitation::HalfSpace> out;
  if (options.table >= 0) {  // every frame origin past the first two above the table, "down" along gravity
    if (!(d.gravity.norm() > 0))
      throw UsageError("--table: the model has no gravity to tell down from up; use --half-space");
    for (int f = 3; f <= frames; ++f)
      out.push_back({fmt::format("table@{}", f), f, d.gravity.normalized(), options.table});
  }
  for (const auto& spec : options.half_spaces) {
    const auto colon = spec.find(':'), last = spec.rfind(':');
    if (colon == std::string::npos || last == colon)
      throw UsageError("--half-space takes frame:nx,ny,nz:offset, not " + spec);
    const auto frame = numbers_of(spec.substr(0, colon), ',', "--half-space frame");
    const auto normal = numbers_of(spec.substr(colon + 1, last - colon - 1), ',', "--half-space normal");
    const auto offset = numbers_of(spec.substr(last + 1), ',', "--half-space offset");
    if (frame.size() != 1 || normal.size() != 3 || offset.size() != 1 || frame[0] < 1 || frame[0] > frames)
      throw UsageError(
          fmt::format("--half-space {}: a frame 1..{}, a normal of 3 numbers and an offset", spec, frames));
    Eigen::Vector3d nv(normal[0], normal[1], normal[2]);
    if (!(nv.norm() > 0)) throw UsageError("--half-space " + spec + ": the normal is zero");
    out.push_back({spec, static_cast<int>(frame[0]), nv.normalized(), offset[0] / nv.norm()});
  }
  return out;
}

// The speed limits of a design file's fastest level per joint (velocity f v, acceleration f^2 a):
// the optimized series move no faster than the structured families.
void fastest_level(const YAML::Node& design, int n, Eigen::VectorXd& velocity, Eigen::VectorXd& acceleration) {
  velocity.resize(n);
  acceleration.resize(n);
  for (int j = 0; j < n; ++j) {
    const std::string c = design["joint_class"][j].as<std::string>();
    double f = 0;
    for (const auto& level : design["speed_factors"][c]) f = std::max(f, level.as<double>());
    velocity(j) = f * design["limits"]["velocity"][j].as<double>();
    acceleration(j) = f * f * design["limits"]["acceleration"][j].as<double>();
  }
}

// The design options of one series from rest at `posture`.
excitation::ExcitationDesignOptions design_options(const ExciteOptions& options, const PeriodRung& rung,
                                                   const YAML::Node& design, const std::string& posture,
                                                   const Eigen::VectorXd& lower, const Eigen::VectorXd& upper,
                                                   const Eigen::VectorXd& velocity, const Eigen::VectorXd& acceleration,
                                                   const Eigen::VectorXd& nominal,
                                                   const identify::ModelDescription& d) {
  const int n = d.nq;
  excitation::ExcitationDesignOptions eo;
  eo.period = rung.period;
  eo.harmonics = rung.harmonics;
  eo.start.resize(n);
  for (int j = 0; j < n; ++j) eo.start(j) = design["postures"][posture][j].as<double>() * kDeg;
  eo.limits.lower = lower.cwiseMin(eo.start - Eigen::VectorXd::Constant(n, 1e-3));
  eo.limits.upper = upper.cwiseMax(eo.start + Eigen::VectorXd::Constant(n, 1e-3));
  eo.limits.velocity = velocity;
  eo.limits.acceleration = acceleration;
  if (nominal.size() > 0) {
    eo.nominal = nominal;
    eo.limits.torque.resize(n);
    for (int j = 0; j < n; ++j)
      eo.limits.torque(j) = options.torque_fraction * d.joints[static_cast<std::size_t>(j)].effort;
  }
  eo.workspace = half_spaces(options, d);
  eo.starts = options.starts;
  eo.held = options.wrist.held;
  eo.parameter_map = options.wrist.map;
  return eo;
}

// Where the structured families cross a half-space (they know the joint limits only), every
// 10 ms: one line per trajectory, its worst crossing.
void warn_crossings(const std::vector<trajectory::Trajectory>& all, const std::vector<excitation::HalfSpace>& spaces,
                    const identify::ModelDescription& d) {
  if (spaces.empty()) return;
  for (const auto& t : all) {
    if (t.family == "OF") continue;  // designed inside them
    Eigen::VectorXd q(d.nq), qd(d.nq), qdd(d.nq);
    double worst = 0, when = 0;
    std::string where;
    for (double time = 0; time <= t.duration(); time += 0.01) {
      t.evaluate(time, q, qd, qdd);
      const Eigen::VectorXd v = excitation::half_space_values(d.frames, q, spaces);
      Eigen::Index h = 0;
      if (v.maxCoeff(&h) > worst) worst = v(h), when = time, where = spaces[static_cast<std::size_t>(h)].name;
    }
    if (worst > 0)
      fmt::print(
          "warning: {} takes a frame {:.3f} m beyond {} at t = {:.2f} s: the structured families know the joint "
          "limits, not the surroundings; edit their postures or amplitudes\n",
          t.name, worst, where, when);
  }
}

// A regressor's two measures the choice compares: column-scaled kappa, log det per sample.
ReferenceMeasures measures_of(const std::string& name, const Eigen::MatrixXd& W, const identify::ModelDescription& d) {
  const RegressorFactor f = RegressorFactor::of(W);
  return {name, excitation::excitation_quality_of_factor(f.R, f.rows, d.parameters, 0).kappa_scaled,
          log_det_per_sample(f, d.nq)};
}

// The optimized series of one run: the design of one series from the postures in turn, and its
// measures as the quality table rates them.
struct SeriesDesigner {
  const ExciteOptions& o;
  const identify::IdentificationModel& model;
  const YAML::Node& design;
  const std::string& text;  // the structured families' design
  const TrajectoryOptions& to;
  const Eigen::VectorXd &lower, &upper, &velocity, &acceleration, &nominal;
  std::vector<std::string> postures;
  std::size_t next = 0;  // the posture the next series starts from

  struct Series {
    excitation::ExcitationDesign r;
    excitation::ExcitationDesignOptions eo;
    PeriodRung rung;
    std::string posture, refused, yaml;
    ReferenceMeasures measures;  // with targets
    bool best_start = true;      // the start kept is the one of the largest log det
  };

  // Series k at `rung`: a posture whose rest already breaks a limit (a table above the arm there,
  // gravity beyond a drive) is skipped for the next one; no posture left: `posture` is empty.
  // With targets, the start kept is the one of the largest log det among those that meet them
  // (the largest of all when none does): the criterion, log det with the first start's column
  // scales, and the targets, the design's own scaled kappa and log det per sample, do not rank
  // the starts alike.
  Series series(int k, const PeriodRung& rung, const ExcitationTargets& targets) {
    Series out = designed(k, rung);
    if (out.posture.empty()) return out;
    out.yaml = yaml_of(out);
    if (targets.any()) {
      out.measures = measures(out);
      if (!targets.met_by(out.measures.kappa_scaled, out.measures.per_sample)) keep_a_start_that_meets(out, targets);
    }
    print(out);
    return out;
  }

  Series designed(int k, const PeriodRung& rung) {
    Series out;
    out.rung = rung;
    const identify::ModelDescription& d = model.description();
    for (std::size_t tries = 0; tries < postures.size() && out.posture.empty(); ++tries, ++next) {
      const std::string candidate = postures[next % postures.size()];
      out.eo = design_options(o, rung, design, candidate, lower, upper, velocity, acceleration, nominal, d);
      out.eo.name = fmt::format("{}{:02d}", o.payload ? "PL" : "OF", k + 1);
      out.eo.seed = o.seed + static_cast<std::uint64_t>(k);
      try {
        out.r = excitation::design_excitation(model, out.eo);
        out.posture = candidate;
      } catch (const excitation::ExcitationInfeasible& e) {
        fmt::print("{} from {}: refused: {}\n", out.eo.name, candidate, e.what());
        out.refused += fmt::format("{}{}: {}", out.refused.empty() ? "" : "; ", candidate, e.what());
      }
    }
    return out;
  }

  std::string yaml_of(const Series& s) const {
    return "\n" + trajectory::fourier_trajectory_yaml(
                      s.eo.name, s.posture, s.r.trajectory, o.periods,
                      fmt::format("Optimized (D-optimal{}) from rest at {}: log det {:.4g}, period "
                                  "{:.3g} s, {} harmonics",
                                  o.payload ? " for a payload's 10 parameters" : "", s.posture, s.r.criterion,
                                  s.rung.period, s.rung.harmonics));
  }

  // The other passed starts in order of log det: the first that meets the targets replaces the
  // series' design.
  void keep_a_start_that_meets(Series& s, const ExcitationTargets& targets) const {
    std::vector<std::size_t> order;
    for (std::size_t i = 0; i < s.r.starts.size(); ++i)
      if (s.r.starts[i].passed && static_cast<int>(i) != s.r.chosen) order.push_back(i);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return s.r.starts[a].criterion > s.r.starts[b].criterion; });
    for (const std::size_t i : order) {
      Series other = s;
      other.r.chosen = static_cast<int>(i);
      other.r.trajectory = s.r.starts[i].trajectory;
      other.r.criterion = s.r.starts[i].criterion;
      other.yaml = yaml_of(other);
      other.measures = measures(other);
      if (!targets.met_by(other.measures.kappa_scaled, other.measures.per_sample)) continue;
      other.r.slack = excitation::check_excitation(model, other.r.trajectory, other.eo);
      other.best_start = false;
      s = std::move(other);
      return;
    }
  }

  void print(const Series& out) const {
    const auto& r = out.r;
    std::string starts;
    for (std::size_t s = 0; s < r.starts.size(); ++s)
      starts +=
          fmt::format("{}{}{:.2f} ({}, {} it, {:.1f} s{})", s ? "; " : "", static_cast<int>(s) == r.chosen ? "*" : "",
                      r.starts[s].criterion, r.starts[s].status, r.starts[s].iterations, r.starts[s].seconds,
                      r.starts[s].passed    ? ""
                      : !r.starts[s].solved ? ", no design"
                                            : ", fails " + r.starts[s].worst.constraint);
    fmt::print("{} from {} (period {:.3g} s, {} harmonics): log det {:.2f} in {:.1f} s; starts: {}{}\n", out.eo.name,
               out.posture, out.rung.period, out.rung.harmonics, r.criterion, r.seconds, starts,
               out.best_start ? "" : "; * the start of the largest log det that meets the targets");
    std::string tight;
    for (const auto& s : r.slack)
      tight += fmt::format("{}{} {:.3g} ({}, t = {:.2f} s)", tight.empty() ? "" : ", ", s.constraint, s.slack, s.where,
                           s.time);
    fmt::print("  tightest limits (dense check every 1 ms): {}\n", tight);
  }

  // A designed series' measures as the quality table rates it (its holds included).
  ReferenceMeasures measures(const Series& s) const {
    const fs::path tmp = fs::path(o.out) / "trajectories.yaml.choice";
    io::write_file_atomically(tmp, text + (text.empty() || text.back() == '\n' ? "" : "\n") + s.yaml);
    Eigen::MatrixXd W;
    try {
      W = trajectory_regressor(
          model, trajectory::TrajectoryDesign::read(tmp, model.description().joints).build(s.eo.name), to);
    } catch (...) {
      fs::remove(tmp);
      throw;
    }
    fs::remove(tmp);
    return measures_of(s.eo.name, W, model.description());
  }
};

// The periods the series are designed at, and what they must reach: one period (--period or
// from the limits) without targets; with --kappa-target, or --compare and neither --period nor
// --harmonics, the ladder up to --max-duration and the targets (dynid_excite_choice.hpp).
std::vector<PeriodRung> series_ladder(const SeriesDesigner& sd, double first_period, ExcitationTargets& targets) {
  const ExciteOptions& o = sd.o;
  const bool choose = o.kappa_target > 0 || (!o.compare.empty() && o.period == 0 && !o.harmonics_given);
  if (!choose || o.optimized == 0) return {{first_period, o.harmonics}};
  std::vector<ReferenceMeasures> references;
  for (const auto& file : o.compare) {
    double duration = 0;
    references.push_back(measures_of(fs::path(file).stem().string(),
                                     reference_regressor(sd.model, file, sd.to, duration), sd.model.description()));
  }
  targets = excitation_targets(o.kappa_target, references);
  const double holds = sd.design["timing"]["start_hold"].as<double>() + sd.design["timing"]["end_hold"].as<double>();
  const double longest = (o.max_duration - holds) / o.periods;
  if (longest < 0.5)
    throw UsageError(fmt::format("--max-duration {:.3g} s leaves no period after the design's holds ({:.3g} s)",
                                 o.max_duration, holds));
  return period_ladder(first_period, o.harmonics, longest);
}

// The optimized series' YAML. With targets, each series climbs the ladder from the period the
// one before it was kept at until it meets them (or keeps its lowest scaled kappa). A series no
// posture can start ends the run there: `failure` says why (thrown at the first).
std::string optimized_series(const Common& common, SeriesDesigner& sd, const std::string& nominal_from,
                             std::string& failure) {
  const ExciteOptions& o = sd.o;
  const identify::ModelDescription& d = sd.model.description();
  ExcitationTargets targets;
  const std::vector<PeriodRung> ladder =
      series_ladder(sd, o.period > 0 ? o.period : auto_period(sd.lower, sd.upper, sd.velocity), targets);
  if (o.optimized == 0) return "";
  std::string periods;
  for (const auto& r : ladder)
    periods += fmt::format("{}{:.3g} s ({} harmonics)", periods.empty() ? "" : ", ", r.period, r.harmonics);
  fmt::print(
      "optimized excitation of {} model {} ({} base parameters): period {}, {} starts each; limits: the box, the "
      "structured families' fastest level, torque {:.0f} % of effort{}\n",
      common.robot, d.variant.empty() ? "full" : d.variant, d.np,
      targets.any() ? "chosen for " + targets.text + " among " + periods : periods, o.starts, 100 * o.torque_fraction,
      nominal_from.empty() ? " (not enforced)" : " (" + nominal_from + ")");
  std::string out;
  std::size_t at = 0;  // the ladder's rung the last series was kept at
  for (int k = 0; k < o.optimized; ++k) {
    SeriesDesigner::Series kept;
    ReferenceMeasures best{"", std::numeric_limits<double>::infinity(), 0};
    const std::size_t from_posture = sd.next;
    std::size_t kept_next = from_posture, kept_at = at;
    for (std::size_t i = at; i < ladder.size(); ++i) {
      sd.next = from_posture;
      SeriesDesigner::Series tried = sd.series(k, ladder[i], targets);
      if (tried.posture.empty()) {
        kept.refused = tried.refused;
        continue;
      }
      const ReferenceMeasures m = targets.any() ? tried.measures : best;
      const std::string missed = targets.missed_by(m.kappa_scaled, m.per_sample);
      if (targets.any())
        fmt::print("  scaled kappa {:.4g}, logdet/N {:.4g}: {}\n", m.kappa_scaled, m.per_sample,
                   missed.empty() ? "meets the targets" : missed);
      if (kept.posture.empty() || m.kappa_scaled < best.kappa_scaled || missed.empty()) {
        best = m, kept = std::move(tried), kept_next = sd.next, kept_at = i;
      }
      if (missed.empty() || !targets.any()) break;
    }
    if (kept.posture.empty()) {
      // Nothing designed yet: nothing to keep. Else the series so far are written first.
      failure = fmt::format("excite OF{:02d}: no posture can start it: {}", k + 1, kept.refused);
      if (k == 0) throw UsageError(failure);
      break;
    }
    sd.next = kept_next, at = kept_at;
    if (targets.any() && !targets.met_by(best.kappa_scaled, best.per_sample))
      fmt::print(
          "{}: no period up to --max-duration {:.3g} s meets the targets; kept period {:.3g} s, the lowest scaled "
          "kappa "
          "(more --starts, a longer --max-duration or more --harmonics may reach them)\n",
          kept.eo.name, o.max_duration, ladder[at].period);
    out += kept.yaml;
  }
  return out;
}

// The nominal model's phi for the torque limits: --params, else robot.yaml's nominal, else none
// (empty; said on stderr). `from` names it.
Eigen::VectorXd nominal_phi(const Common& common, const ExciteOptions& options,
                            const identify::IdentificationModel& model, std::string& from) {
  const identify::ModelDescription& d = model.description();
  std::vector<std::string> names;
  for (const auto& p : d.parameters) names.push_back(p.name);
  if (!options.params.empty()) {
    from = options.params;
    return io::read_parameters_yaml(options.params, names);
  }
  if (std::vector<double> s; nominal_standard_parameters(common, d.standard, s)) {
    from = "robot.yaml nominal";
    return model.base_from_standard(Eigen::Map<const Eigen::VectorXd>(s.data(), static_cast<Eigen::Index>(s.size())));
  }
  fmt::print(stderr, "excite: {} has no nominal parameters and no --params was given: torque limits are NOT enforced\n",
             (common.robot_dir() / "robot.yaml").string());
  return {};
}

void run(const Common& common, const ExciteOptions& given, bool periods_given) {
  ExciteOptions options = given;
  const auto model = identification_model(common, options.payload ? "full" : options.model);
  if (options.payload) {
    options.wrist = payload_setup(*model, options.model, options.payload_joints, options.period, options.harmonics,
                                  options.harmonics_given, options.periods, periods_given);
    options.optimized = 1;
  }
  const identify::ModelDescription& d = model->description();
  const int n = d.nq;
  const fs::path design_file = fs::path(options.out) / "trajectories.yaml";
  // Like import, control and export: what is there stays unless the user says so.
  for (const fs::path& f : {design_file, fs::path(options.out) / "quality.txt"})
    if (fs::exists(f) && !options.force)
      throw UsageError(
          fmt::format("{} exists: dynid excite does not replace it; choose another -o, or --force", f.string()));
  fs::create_directories(options.out);

  // 1. The structured families.
  std::string text;
  trajectory::StructuredDesignOptions so;
  so.robot = common.robot;
  so.joints = d.joints;
  so.seed = options.seed;
  if (!options.from_design.empty()) {
    text = io::read_text_file(options.from_design);
  } else {
    try {
      text = trajectory::structured_design_yaml(so);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
  }
  const YAML::Node design = io::load_yaml_text(
      text, options.from_design.empty() ? std::string("the structured design") : options.from_design);
  // Another robot's design was reported at the temporary file it became (its joints differ).
  if (!options.from_design.empty()) {
    const YAML::Node robot = design.IsMap() ? design["robot"] : YAML::Node();
    if (!robot || !robot.IsScalar())
      throw UsageError(
          fmt::format("{}: no `robot:`: --from-design takes a trajectory design of {} (e.g. its trajectories.yaml)",
                      options.from_design, common.robot));
    if (robot.as<std::string>() != common.robot)
      throw UsageError(
          fmt::format("{}:{}: the design is of robot '{}', not {}: --from-design takes a design of the robot "
                      "being excited",
                      options.from_design, robot.Mark().line + 1, robot.as<std::string>(), common.robot));
  }
  Eigen::VectorXd velocity, acceleration;
  fastest_level(design, n, velocity, acceleration);
  wrist_limits(options.wrist, d, velocity, acceleration);
  const double margin = design["limits"]["position_margin"].as<double>() * kDeg;
  so.position_margin = margin;
  Eigen::VectorXd lower, upper;
  trajectory::structured_box(so, lower, upper);

  // 2. The nominal model for the torque limits.
  std::string nominal_from;
  const Eigen::VectorXd nominal = nominal_phi(common, options, *model, nominal_from);

  // 3. The optimized series, one per posture in turn, each from rest at its posture.
  TrajectoryOptions to;
  to.interval_ms = options.interval_ms;
  to.compare = options.compare;
  SeriesDesigner designer{options, *model, design, text, to, lower, upper, velocity, acceleration, nominal};
  for (const auto& p : design["postures"]) designer.postures.push_back(p.first.as<std::string>());
  std::string failure;
  const std::string optimized_text = optimized_series(common, designer, nominal_from, failure);
  if (options.optimized > 0 && text.find("\ntrajectories:") == std::string::npos)
    throw UsageError("the design has no trajectories list");
  // A payload's design holds its wrist motion alone.
  if (options.payload) text = text.substr(0, text.find("\ntrajectories:") + 1) + "trajectories:\n";
  const std::string full = text + (text.empty() || text.back() == '\n' ? "" : "\n") + optimized_text;
  // Read back before it is kept: the file must build, every trajectory inside its limits.
  const fs::path tmp = fs::path(options.out) / "trajectories.yaml.new";
  io::write_file_atomically(tmp, full);
  std::vector<trajectory::Trajectory> all;
  try {
    const auto check = trajectory::TrajectoryDesign::read(tmp, d.joints);
    for (const auto& name : check.names()) all.push_back(check.build(name));
  } catch (...) {
    fs::remove(tmp);
    throw;
  }
  fs::rename(tmp, design_file);
  fmt::print("{}: {} trajectories\n", design_file.string(), all.size());
  warn_crossings(all, half_spaces(options, d), d);

  // 4. The excitation quality of each, side by side (a payload's: of its 10 parameters).
  std::string table;
  if (options.payload)
    for (const auto& t : all) table += payload_quality(*model, options.wrist, t, to);
  else
    table = trajectory_quality_table(common, all, to, options.model);
  fmt::print("{}", table);
  io::write_file_atomically(fs::path(options.out) / "quality.txt", table);
  if (!failure.empty())
    throw UsageError(failure + fmt::format(" ({} keeps the series designed before it)", design_file.string()));
}

}  // namespace

void add_excite_commands(CLI::App& app, Common& common) {
  auto o = std::make_shared<ExciteOptions>();
  auto* cmd = app.add_subcommand("excite",
                                 "Identification trajectories for any robot: the structured families and optimized "
                                 "Fourier series, in one design file, with their excitation quality");
  add_robot_options(cmd, common);
  cmd->add_option("-o,--output", o->out, "Write trajectories.yaml and quality.txt here")->required();
  cmd->add_option("--model", o->model,
                  "The model whose base parameters are excited (default: robot.yaml's identified)");
  cmd->add_option("--from-design", o->from_design,
                  "Take the structured families from this design file (e.g. the robot's "
                  "trajectories.yaml) instead of generating them")
      ->check(CLI::ExistingFile);
  cmd->add_option("--params", o->params,
                  "Nominal parameters of --model for the torque limits (default: robot.yaml's nominal)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--optimized", o->optimized, "Optimized trajectories (OF01...), from the postures in turn")
      ->check(numbers::count(0, 99))
      ->capture_default_str();
  auto* harmonics = cmd->add_option("--harmonics", o->harmonics,
                                    "Harmonics of each series (with a period chosen: of its first "
                                    "period, 1.5 more per doubling)")
                        ->check(numbers::count(2, 20))
                        ->capture_default_str();
  auto* period = cmd->add_option("--period", o->period,
                                 "Period of each series, s (default: from the joints' box and speed, 5-60 "
                                 "s; with --compare or --kappa-target, chosen to meet them)")
                     ->check(numbers::checked(0.5, 3600, false, false, "from 0.5 to 3600 s"));
  cmd->add_option("--kappa-target", o->kappa_target,
                  "Choose the period and the harmonics for a first series whose column-scaled "
                  "kappa is below this (and that beats every --compare reference on scaled "
                  "kappa and log det per sample)")
      ->check(numbers::checked(1, 1e6, false, false, "from 1 to 1e6"))
      ->excludes(period);
  cmd->add_option("--max-duration", o->max_duration,
                  "Longest optimized trajectory, holds included, s, when the period is chosen")
      ->check(numbers::checked(1, 3600, false, false, "from 1 to 3600 s"))
      ->capture_default_str();
  auto* periods = cmd->add_option("--periods", o->periods, "Periods each optimized trajectory runs")
                      ->check(numbers::count(1, 100))
                      ->capture_default_str();
  cmd->add_option("--starts", o->starts, "Random starts of each optimization")
      ->check(numbers::count(1, 100))
      ->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed of the starts and of the validation waypoints")
      ->capture_default_str()
      ->check(numbers::seed());
  cmd->add_option("--torque-fraction", o->torque_fraction, "Torque limit as a fraction of each joint's effort limit")
      ->check(numbers::checked(0.01, 1, false, false, "from 0.01 to 1"))  // CLI::Range let NaN through
      ->capture_default_str();
  cmd->add_option("--table", o->table,
                  "A table this far below frame 0's origin (m, along gravity): every frame origin "
                  "from 3 on stays above it (1 cm clearance)")
      ->check(
          numbers::checked(0, 100, false, false, "from 0 to 100 m"));  // -5 meant no table, nan and 1e300 were taken
  cmd->add_option("--half-space", o->half_spaces,
                  "frame:nx,ny,nz:offset: that frame's origin p keeps n.p <= offset (m, frame 0)");
  cmd->add_option("--compare", o->compare,
                  "Logs of reference motions (e.g. a published trajectory's recording, imported) "
                  "rated beside the design in the quality table")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--force", o->force, "Replace trajectories.yaml and quality.txt when -o holds them");
  cmd->add_option("--interval", o->interval_ms, "Sampling interval of the quality table, ms")
      ->check(numbers::interval_ms())
      ->capture_default_str();
  cmd->add_flag("--payload", o->payload,
                "One wrist motion (PL01, 20 s) D-optimal for a payload's 10 inertial parameters, the other "
                "joints holding the posture (dynid payload; docs/payload.md)");
  cmd->add_option("--payload-joints", o->payload_joints, "With --payload: the wrist joints that move")
      ->check(numbers::count(1, 20))
      ->capture_default_str();
  cmd->callback([&common, o, harmonics, periods] {
    o->harmonics_given = harmonics->count() > 0;
    run(common, *o, periods->count() > 0);
  });
}

}  // namespace symoro::dynid
