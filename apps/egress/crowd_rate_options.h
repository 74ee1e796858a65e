#pragma once
// The people's step rates on the command line (`--crowd-rate`, `--crowd-social-rate`), one pair
// for `sim run` and `evac study`.

#include <CLI/CLI.hpp>

#include "commands.h"
#include "egress/twin/twin_model.h"

namespace egress::apps {

/// --crowd-rate and --crowd-social-rate as given (TwinConfig::Validate checks that the crowd
/// rate divides the physics rate and that the social rate does not exceed it).
struct CrowdRateOptions {
  double crowd_rate_hz{twin::TwinConfig{}.crowd_rate_hz};
  double crowd_social_rate_hz{0.0};  ///< 0: every crowd step

  /// Registers both options on `command` (each a finite rate up to the physics rate).
  void AddTo(CLI::App& command) {
    const double physics = twin::TwinConfig{}.physics_rate_hz;
    command
        .add_option("--crowd-rate", crowd_rate_hz,
                    "step the people at this rate, 240 Hz divided by a whole number [Hz] "
                    "(TwinConfig::crowd_rate_hz)")
        ->capture_default_str()
        ->check(FiniteIn(1.0, physics));
    command
        .add_option("--crowd-social-rate", crowd_social_rate_hz,
                    "sum the people's social terms at this rate, held between [Hz] (default: "
                    "every crowd step; TwinConfig::crowd_social_rate_hz)")
        ->check(FiniteIn(1.0, physics));
  }

  /// Both rates into `config` (the social rate defaulting to the crowd rate).
  void ApplyTo(twin::TwinConfig& config) const {
    config.crowd_rate_hz = crowd_rate_hz;
    config.crowd_social_rate_hz = crowd_social_rate_hz > 0.0 ? crowd_social_rate_hz : crowd_rate_hz;
  }
};

}  // namespace egress::apps
