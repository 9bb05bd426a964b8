// The localization stage of `dynid diagnose`: where, in the motion, in frequency and in time,
// a model's torque disagrees with the measurement. Given per trajectory the measured torque and
// the model's prediction on a uniform grid, the residual r = tau_measured - tau_model of every
// joint is broken down by motion regime (velocity reversals, high acceleration, position bands,
// direction), by frequency (Welch spectrum, power per band) and by time shift (the lag that best
// aligns measurement and model, the lag of r behind the velocity). Each pattern points at a cause:
// SSE concentrated at reversals and a direction step = Coulomb friction (or backlash); power
// below 0.5 Hz = a pose-dependent (gravity, offset) error; a torque lag = an unmodelled delay or
// a filter mismatch; r following qd at zero lag = viscous friction.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/preprocess/preprocess.hpp"

namespace symoro::diagnose {

// One trajectory (or one piece of it) on a uniform grid. qd is the preprocessed (zero-phase
// low-passed) velocity, so its sign changes are reversals of the motion, not sensor noise.
struct ResidualSeries {
  std::string name;                                     // trajectory name (pieces of one trajectory share it)
  double interval = 0;                                  // s
  Eigen::VectorXd time;                                 // s
  Eigen::MatrixXd q, qd, qdd, tau_measured, tau_model;  // samples x joints
};

// preprocess() output and the model's torque at its samples, split where Samples::piece changes
// (lags and spectra must not run across a gap). The pieces keep `name`.
std::vector<ResidualSeries> residual_series(const std::string& name, const preprocess::Samples& samples,
                                            const Eigen::MatrixXd& tau_model);

struct LocalizeOptions {
  double reversal_window = 0.05;  // s, +- around each sign change of qd
  // rad/s: |qd| above it is motion in one direction; at or below it, slow (counted as reversal).
  // It is also the hysteresis of reversal detection, so sensor chatter around zero is no reversal.
  double direction_velocity = 0.02;
  double high_acceleration_quantile = 0.8;  // |qdd| above this quantile (pooled per joint)
  int position_bands = 4;                   // quantile bands of q
  // Hz, ascending lower edges of the power bands; the last band runs to Nyquist. Power below the
  // first edge (if it is above 0) is in no band, so the fractions then add up to less than one.
  std::vector<double> band_edges{0, 0.5, 2, 5};
  // Welch segments: the power of two of samples lasting segment_seconds or just more (so
  // [1, 2) x segment_seconds), shortened to the longest series when none is that long.
  double segment_seconds = 2.0;
  double max_lag = 0.1;  // s, the lag searches cover +- max_lag
};

// The residual over the samples of one regime. Shares are relative to the joint's all samples.
struct RegimeStat {
  std::string regime;  // e.g. "velocity reversal", "q in [-0.52, 0.31] rad ([-29.8, 17.8] deg)"
  int samples = 0;
  double fraction = 0;       // of the joint's samples
  double mean = 0, rms = 0;  // N m (NaN without samples)
  double rms_ratio = 0;      // rms / the joint's overall residual rms
  double sse_share = 0;      // share of the joint's residual sum of squares
};

struct JointLocalization {
  int joint = 0;  // 0-based column
  std::string name;
  double residual_rms = 0, torque_rms = 0;  // N m; torque_rms of the measured torque
  // In this order: "velocity reversal", "high acceleration ...", the position bands (ascending q),
  // "qd > +v0", "qd < -v0".
  std::vector<RegimeStat> regimes;
  // (mean(r | qd > v0) - mean(r | qd < -v0)) / 2: the Coulomb signature, N m. Its standard error
  // counts the residual's autocorrelation: the variance of each group mean is inflated by
  // N / N_eff = 1 + 2 sum_k rho_k (effective_sample_size) of the residual minus its group's mean
  // (0 on slow samples). A viscous misfit d_fv qd shows here too, as d_fv mean|qd|: tell them
  // apart by velocity_correlation, the reversal share and the residual-vs-velocity figure.
  double direction_step = 0, direction_step_se = 0;
  Eigen::VectorXd band_power_fraction;  // one per Localization::bands, of the residual's power
  double peak_frequency = 0;            // Hz, of the residual PSD (log-parabolic refinement)
  double torque_lag = 0;                // s, + = measured lags model (see torque_lag)
  // The same with an offset, a Coulomb step (sign qd, 0 when |qd| <= v0) and a viscous term
  // (qd) of the residual fitted at every delta. A friction misfit correlates with the torque's
  // derivative (d tau / dt ~ qd) and so biases torque_lag, by tens of ms for a Coulomb misfit of
  // a few % of the torque; this one is not biased by it (but a delay whose effect is
  // indistinguishable from viscous friction is then absorbed too).
  double torque_lag_adjusted = 0;
  // Peak of the normalized cross-correlation of r and qd (largest |c|, signed): + lag = r lags qd.
  double velocity_lag = 0, velocity_correlation = 0;
  std::string summary;  // one line for people
};

// One-sided PSD, (N m)^2/Hz, columns = joints. Not detrended: a constant residual is power at
// 0 Hz, so integrating the residual PSD gives its mean square (residual_rms^2), the quantity
// the regime shares split.
struct Spectrum {
  Eigen::VectorXd frequency;             // Hz, 0 .. Nyquist
  Eigen::MatrixXd residual, measured;    // frequencies x joints
  int segments = 0, segment_length = 0;  // averaged over all series
};

struct Localization {
  std::vector<JointLocalization> joints;
  Spectrum spectrum;
  std::vector<std::string> bands;  // "[0, 0.5) Hz", ..., "[5, 50] Hz" (the last up to Nyquist)
  double interval = 0;             // s, common to every series
  int series = 0, samples = 0;     // series used (non-empty), samples per joint
};

// Throws std::invalid_argument when the series are empty, of inconsistent shapes, intervals or
// joint counts, not on a uniform grid (spacing off `interval` by more than 0.1 %), or hold a
// non-finite value; when joint_names is neither empty (then "joint 1", ...) nor one per joint;
// or when an option is out of range.
Localization localize(const std::vector<ResidualSeries>& series, const std::vector<std::string>& joint_names,
                      const LocalizeOptions& options = {});

// --- Building blocks (exposed for tests and reuse) -------------------------------------------

// The Welch segment length for `interval`: the smallest power of two >= segment_seconds / interval.
int welch_segment_length(double interval, double segment_seconds);

struct Psd {
  Eigen::VectorXd frequency;  // Hz, k / (segment_length interval), k = 0 .. segment_length / 2
  Eigen::MatrixXd power;      // one-sided density, (unit)^2/Hz, frequencies x columns
  int segments = 0, segment_length = 0;
};

// Welch's method on the columns of every piece (all sampled at `interval`, same column count):
// periodic Hann window, 50 % overlap, no detrending; the segments of all pieces are averaged
// with equal weight (pieces shorter than a segment contribute none; the unused remainder of a
// piece is split evenly between its ends). segment_length must be even and >= 4. With no
// segment at all, frequency and power are empty (segments = 0).
Psd welch(const std::vector<Eigen::MatrixXd>& pieces, double interval, int segment_length);

// The delay delta (s) minimizing sum (measured(t) - model(t - delta))^2 over |delta| <= max_lag,
// summed over the pieces (measured[i] and model[i] of equal length): an integer-sample scan,
// then a golden-section search within +-1 sample of the best, the model shifted by Catmull-Rom
// interpolation. Every delta is scored on the same samples (those at least max_lag + 3 samples
// from a piece's ends), so costs compare. + = the measurement lags the model. NaN when no piece
// is long enough. With `nuisance` (one samples x p matrix per piece, aligned with `measured`),
// the cost at every delta is the least-squares residual after fitting those columns (pooled
// coefficients) to measured(t) - model(t - delta): the lag of what they cannot explain.
double torque_lag(const std::vector<Eigen::VectorXd>& measured, const std::vector<Eigen::VectorXd>& model,
                  double interval, double max_lag, const std::vector<Eigen::MatrixXd>& nuisance = {});

struct CrossCorrelationPeak {
  double lag = std::numeric_limits<double>::quiet_NaN();          // s, + = x lags y
  double correlation = std::numeric_limits<double>::quiet_NaN();  // in [-1, 1]
};
// c(delta) = Pearson correlation of x(t) and y(t - delta) over the same samples for every integer
// delta (as torque_lag; pooled over pieces, each signal's pooled mean removed); the delta with the
// largest |c| over |delta| <= max_lag, refined by a parabola through its neighbours.
CrossCorrelationPeak cross_correlation_peak(const std::vector<Eigen::VectorXd>& x,
                                            const std::vector<Eigen::VectorXd>& y, double interval, double max_lag);

// N_eff = N / (1 + 2 sum_{k>=1} rho_k) of the pooled pieces, rho_k the lag-k autocorrelation
// (products only within a piece, pooled mean removed; FFT), the sum stopped before the first
// rho_k <= 0 (so N_eff <= N). For AR(1) with coefficient a: about N (1 - a) / (1 + a).
double effective_sample_size(const std::vector<Eigen::VectorXd>& pieces);

// The p-quantile of `values` with linear interpolation between order statistics (position
// p (n - 1)); NaN when empty.
double quantile(std::vector<double> values, double p);

}  // namespace symoro::diagnose
