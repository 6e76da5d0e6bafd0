#pragma once
// Online adaptive element of the trajectory follower (Johnson and Kannan's
// adaptive trajectory controller): one single-hidden-layer neural network
// per loop, inputs the normalised states, tracking errors, pseudo-controls
// and a bias, trained online on the reference-model tracking error with
// e-modification and a norm bound on the weights. Pseudo-control hedging in
// the controller keeps actuator limits and inner-loop lag out of the error
// it learns from. Pure core.

#include <cstdint>

#include <Eigen/Dense>

#include "ofn/controller/trajectory_controller.hpp"

namespace ofn::control {

/// Learning rates and bounds of one network.
struct NetworkSettings {
  int hidden = 8;                 // hidden neurons
  double output_rate = 1.0;       // Gamma_W, output-layer learning rate
  double hidden_rate = 1.0;       // Gamma_V, hidden-layer learning rate
  double e_modification = 0.5;    // kappa: leakage proportional to the error norm
  double max_weight_norm = 20.0;  // projection bound on each layer's Frobenius norm
  double max_output = 5.0;        // bound on each output component
  // Error norm below which the weights stay put, with full learning from
  // twice this: without it the network keeps chasing sensor noise and
  // the yaw sweep, and its output shakes a well-modelled airframe.
  double dead_zone = 0.0;
};

struct AdaptiveConfig {
  bool enabled = true;  // false: the non-adaptive baseline (reference models and hedging stay)
  NetworkSettings outer{8, 4.0, 1.0, 0.05, 20.0, 5.0, 0.5};       // outputs m/s^2
  NetworkSettings inner{8, 100.0, 20.0, 0.005, 50.0, 20.0, 0.2};  // outputs rad/s^2
  uint32_t seed = 7;                                              // initial hidden-layer weights
};

/// One single-hidden-layer network: nu = W^T sigma(V^T x_bar), x_bar and
/// sigma_bar with a bias entry. Inputs must already be normalised.
class NeuralNetwork {
 public:
  NeuralNetwork(int inputs, int outputs, const NetworkSettings& settings, uint32_t seed);

  /// Forward pass; keeps the activations for the next update().
  Eigen::VectorXd evaluate(const Eigen::VectorXd& inputs);
  /// One step of the update law for the last evaluated input:
  /// W' = -Gamma_W [(sigma - sigma' V^T x) r^T + kappa |e| W],
  /// V' = -Gamma_V [x r^T W^T sigma' + kappa |e| V], then the norm bound.
  /// `r` is e^T P B of the loop's error dynamics.
  void update(const Eigen::VectorXd& r, double error_norm, double dt);
  void reset();

  double output_weight_norm() const { return w_.norm(); }
  double hidden_weight_norm() const { return v_.norm(); }

 private:
  NetworkSettings settings_;
  Eigen::MatrixXd v_, v_initial_;  // (inputs + 1) x hidden
  Eigen::MatrixXd w_;              // (hidden + 1) x outputs
  Eigen::VectorXd x_bar_, z_, sigma_bar_, sigma_slope_;
};

/// The adaptive element with a network for each loop.
class NeuralAdaptation final : public AdaptiveElement {
 public:
  explicit NeuralAdaptation(AdaptiveConfig config = {});

  Vec3 outer_output(const AdaptiveInputs& in) override;
  Vec3 inner_output(const AdaptiveInputs& in) override;
  void update(const AdaptiveInputs& in) override;
  void reset() override;
  double weight_norm() const override;

  const NeuralNetwork& outer_network() const { return outer_; }
  const NeuralNetwork& inner_network() const { return inner_; }

  static constexpr int kOuterInputs = 18;
  static constexpr int kInnerInputs = 18;

 private:
  AdaptiveConfig config_;
  NeuralNetwork outer_, inner_;
  bool outer_evaluated_ = false, inner_evaluated_ = false;
};

/// The adaptive element a configuration asks for: the networks, or none.
std::unique_ptr<AdaptiveElement> make_adaptive_element(const AdaptiveConfig& config);

}  // namespace ofn::control
