#include "ofn/controller/neural_adaptation.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace ofn::control {
namespace {

// Inputs are scaled by typical magnitudes and clipped, so that a wild
// estimate saturates a neuron instead of throwing the weights about.
constexpr double kInputClip = 3.0;
// The update law's error signal is clipped likewise: a far-off reference
// (or a glitch) must not jolt the weights in one step.
constexpr double kErrorClip = 5.0;

void put(Eigen::VectorXd& x, int at, const Vec3& v, double scale) {
  for (int i = 0; i < 3; ++i) {
    const double s = v[i] / scale;
    x[at + i] = std::isfinite(s) ? std::clamp(s, -kInputClip, kInputClip) : 0.0;
  }
}

Vec3 to_vec3(const Eigen::VectorXd& v) {
  return Vec3(v[0], v[1], v[2]);
}

void bound_norm(Eigen::MatrixXd& m, double limit) {
  const double n = m.norm();
  if (n > limit) m *= limit / n;
}

}  // namespace

NeuralNetwork::NeuralNetwork(int inputs, int outputs, const NetworkSettings& settings,
                             uint32_t seed)
    : settings_(settings) {
  const int hidden = std::max(1, settings_.hidden);
  // Distinct, small hidden-layer weights so that the neurons start
  // different; raw generator output keeps them the same on every platform.
  std::mt19937 rng(seed);
  v_initial_.resize(inputs + 1, hidden);
  const double scale = 1.0 / std::sqrt(static_cast<double>(inputs + 1));
  for (int j = 0; j < hidden; ++j)
    for (int i = 0; i <= inputs; ++i)
      v_initial_(i, j) = scale * (2.0 * (static_cast<double>(rng()) / 4294967296.0) - 1.0);
  w_ = Eigen::MatrixXd::Zero(hidden + 1, outputs);
  v_ = v_initial_;
  x_bar_ = Eigen::VectorXd::Zero(inputs + 1);
  z_ = Eigen::VectorXd::Zero(hidden);
  sigma_bar_ = Eigen::VectorXd::Zero(hidden + 1);
  sigma_slope_ = Eigen::VectorXd::Zero(hidden);
}

void NeuralNetwork::reset() {
  v_ = v_initial_;
  w_.setZero();
}

Eigen::VectorXd NeuralNetwork::evaluate(const Eigen::VectorXd& inputs) {
  x_bar_[0] = 1.0;
  x_bar_.tail(inputs.size()) = inputs;
  z_ = v_.transpose() * x_bar_;
  sigma_bar_[0] = 1.0;
  for (int j = 0; j < z_.size(); ++j) {
    const double s = 1.0 / (1.0 + std::exp(-z_[j]));
    sigma_bar_[j + 1] = s;
    sigma_slope_[j] = s * (1.0 - s);
  }
  Eigen::VectorXd out = w_.transpose() * sigma_bar_;
  for (int k = 0; k < out.size(); ++k)
    out[k] = std::clamp(out[k], -settings_.max_output, settings_.max_output);
  return out;
}

void NeuralNetwork::update(const Eigen::VectorXd& error_signal, double error_norm, double dt) {
  if (!error_signal.allFinite() || !std::isfinite(error_norm) || !(dt > 0)) return;
  // Dead zone, ramped so that learning does not switch on with a jolt.
  double learning = 1.0;
  if (settings_.dead_zone > 0.0)
    learning = std::clamp(error_norm / settings_.dead_zone - 1.0, 0.0, 1.0);
  if (learning == 0.0) return;
  const Eigen::VectorXd r = error_signal.cwiseMax(-kErrorClip).cwiseMin(kErrorClip);
  const double leak = settings_.e_modification * std::min(error_norm, kErrorClip);
  // sigma_bar - sigma_bar' V^T x_bar: the bias row has no slope.
  Eigen::VectorXd linearised = sigma_bar_;
  linearised.tail(z_.size()) -= sigma_slope_.cwiseProduct(z_);
  // r^T W^T sigma_bar' (a row over the hidden neurons).
  const Eigen::VectorXd back = (w_ * r).tail(z_.size()).cwiseProduct(sigma_slope_);
  const Eigen::MatrixXd w_dot =
      -learning * settings_.output_rate * (linearised * r.transpose() + leak * w_);
  const Eigen::MatrixXd v_dot =
      -learning * settings_.hidden_rate * (x_bar_ * back.transpose() + leak * v_);
  w_ += dt * w_dot;
  v_ += dt * v_dot;
  bound_norm(w_, settings_.max_weight_norm);
  bound_norm(v_, settings_.max_weight_norm);
}

NeuralAdaptation::NeuralAdaptation(AdaptiveConfig config)
    : config_(config),
      outer_(kOuterInputs, 3, config_.outer, config_.seed),
      inner_(kInnerInputs, 3, config_.inner, config_.seed + 1) {}

Vec3 NeuralAdaptation::outer_output(const AdaptiveInputs& in) {
  Eigen::VectorXd x(kOuterInputs);
  put(x, 0, in.velocity, 10.0);
  put(x, 3, in.gravity_body, 1.0);
  put(x, 6, in.pseudo_accel, 5.0);
  put(x, 9, in.position_error, 5.0);
  put(x, 12, in.velocity_error, 2.0);
  put(x, 15, in.nose_world, 1.0);
  outer_evaluated_ = true;
  return to_vec3(outer_.evaluate(x));
}

Vec3 NeuralAdaptation::inner_output(const AdaptiveInputs& in) {
  Eigen::VectorXd x(kInnerInputs);
  put(x, 0, in.body_rates, 1.0);
  put(x, 3, in.attitude_error, 0.2);
  put(x, 6, in.rate_error, 0.5);
  put(x, 9, in.pseudo_angular, 10.0);
  put(x, 12, in.body_velocity, 10.0);
  put(x, 15, in.nose_world, 1.0);
  inner_evaluated_ = true;
  return to_vec3(inner_.evaluate(x));
}

void NeuralAdaptation::update(const AdaptiveInputs& in) {
  if (outer_evaluated_)
    outer_.update(Eigen::Vector3d(in.outer_error_signal), in.outer_error_norm, in.dt);
  if (inner_evaluated_)
    inner_.update(Eigen::Vector3d(in.inner_error_signal), in.inner_error_norm, in.dt);
  outer_evaluated_ = inner_evaluated_ = false;
}

void NeuralAdaptation::reset() {
  outer_.reset();
  inner_.reset();
  outer_evaluated_ = inner_evaluated_ = false;
}

double NeuralAdaptation::weight_norm() const {
  return std::sqrt(
      std::pow(outer_.output_weight_norm(), 2) + std::pow(outer_.hidden_weight_norm(), 2) +
      std::pow(inner_.output_weight_norm(), 2) + std::pow(inner_.hidden_weight_norm(), 2));
}

std::unique_ptr<AdaptiveElement> make_adaptive_element(const AdaptiveConfig& config) {
  if (!config.enabled) return std::make_unique<NoAdaptation>();
  return std::make_unique<NeuralAdaptation>(config);
}

}  // namespace ofn::control
