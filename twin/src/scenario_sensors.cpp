#include "scenario_sensors.h"

namespace egress::twin {

void ParseSensors(const FieldReader& r, const YAML::Node& node, SensorConfig* c) {
  r.CheckKeys(node, "sensors", {"laser", "depth", "odometry", "detector"});
  if (const YAML::Node n = node["laser"]) {
    const std::string f = "sensors.laser";
    r.CheckKeys(n, f,
                {"rate_hz", "fov_deg", "step_deg", "range_min", "range_max", "noise",
                 "glass_max_incidence_deg", "latency_s"});
    if (n["rate_hz"]) c->laser_rate_hz = r.Positive(n["rate_hz"], f + ".rate_hz");
    if (n["fov_deg"]) c->laser_fov_deg = r.Positive(n["fov_deg"], f + ".fov_deg");
    if (n["step_deg"]) c->laser_step_deg = r.Positive(n["step_deg"], f + ".step_deg");
    if (n["range_min"]) c->laser_range_min = r.NonNegative(n["range_min"], f + ".range_min");
    if (n["range_max"]) c->laser_range_max = r.Positive(n["range_max"], f + ".range_max");
    if (n["noise"]) c->laser_noise = r.NonNegative(n["noise"], f + ".noise");
    if (n["glass_max_incidence_deg"]) {
      c->laser_glass_max_incidence_deg =
          r.NonNegative(n["glass_max_incidence_deg"], f + ".glass_max_incidence_deg");
    }
    if (n["latency_s"]) c->laser_latency_s = r.NonNegative(n["latency_s"], f + ".latency_s");
    if (c->laser_fov_deg > 360.0) r.Fail(n["fov_deg"], f + ".fov_deg", "must be at most 360");
  }
  if (const YAML::Node n = node["depth"]) {
    const std::string f = "sensors.depth";
    r.CheckKeys(
        n, f, {"rate_hz", "width", "height", "hfov_deg", "range_max", "noise_coeff", "latency_s"});
    if (n["rate_hz"]) c->depth_rate_hz = r.Positive(n["rate_hz"], f + ".rate_hz");
    if (n["width"]) c->depth_width = int(r.Positive(n["width"], f + ".width"));
    if (n["height"]) c->depth_height = int(r.Positive(n["height"], f + ".height"));
    if (n["hfov_deg"]) c->depth_hfov_deg = r.Positive(n["hfov_deg"], f + ".hfov_deg");
    if (n["range_max"]) c->depth_range_max = r.Positive(n["range_max"], f + ".range_max");
    if (n["noise_coeff"])
      c->depth_noise_coeff = r.NonNegative(n["noise_coeff"], f + ".noise_coeff");
    if (n["latency_s"]) c->depth_latency_s = r.NonNegative(n["latency_s"], f + ".latency_s");
  }
  if (const YAML::Node n = node["odometry"]) {
    const std::string f = "sensors.odometry";
    r.CheckKeys(n, f, {"rate_hz", "noise", "yaw_drift"});
    if (n["rate_hz"]) c->odometry_rate_hz = r.Positive(n["rate_hz"], f + ".rate_hz");
    if (n["noise"]) c->odometry_noise = r.NonNegative(n["noise"], f + ".noise");
    if (n["yaw_drift"]) c->odometry_yaw_drift = r.Number(n["yaw_drift"], f + ".yaw_drift");
  }
  if (const YAML::Node n = node["detector"]) {
    const std::string f = "sensors.detector";
    r.CheckKeys(n, f,
                {"rate_hz", "latency_s", "miss_rate", "false_positive_rate", "min_visible",
                 "lighting", "visibility_samples"});
    if (n["rate_hz"]) c->detector_rate_hz = r.Positive(n["rate_hz"], f + ".rate_hz");
    if (n["latency_s"]) c->detector_latency_s = r.ReadRange(n["latency_s"], f + ".latency_s");
    if (n["miss_rate"]) c->detector_miss_rate = r.Fraction(n["miss_rate"], f + ".miss_rate");
    if (n["false_positive_rate"]) {
      c->detector_false_positive_rate =
          r.Fraction(n["false_positive_rate"], f + ".false_positive_rate");
    }
    if (n["min_visible"])
      c->detector_min_visible = r.Fraction(n["min_visible"], f + ".min_visible");
    if (n["lighting"]) c->detector_lighting = r.Fraction(n["lighting"], f + ".lighting");
    if (n["visibility_samples"]) {
      c->detector_visibility_samples =
          int(r.Positive(n["visibility_samples"], f + ".visibility_samples"));
    }
    if (c->detector_latency_s.min < 0)
      r.Fail(n["latency_s"], f + ".latency_s", "must not be negative");
  }
}

}  // namespace egress::twin
