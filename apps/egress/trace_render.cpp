#include "trace_render.h"

#include <cmath>
#include <fstream>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "commands.h"
#include "egress/perception/image_io.h"

namespace egress::apps {
namespace {

// Maps W (x right, y up) to pixels over the walls' bounds with a 0.5 m margin.
struct View {
  double x0{0}, y1{0}, scale{40};
  int width{0}, height{0};
  cv::Point operator()(double x, double y) const {
    return {int(std::lround((x - x0) * scale)), int(std::lround((y1 - y) * scale))};
  }
};

View MakeView(const TraceFile& trace, double scale) {
  double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
  for (const auto& w : trace.header.at("walls")) {
    const double c = std::abs(std::cos(w[2].get<double>())),
                 s = std::abs(std::sin(w[2].get<double>()));
    const double hx = (c * w[3].get<double>() + s * w[4].get<double>()) / 2;
    const double hy = (s * w[3].get<double>() + c * w[4].get<double>()) / 2;
    x0 = std::min(x0, w[0].get<double>() - hx);
    x1 = std::max(x1, w[0].get<double>() + hx);
    y0 = std::min(y0, w[1].get<double>() - hy);
    y1 = std::max(y1, w[1].get<double>() + hy);
  }
  if (x0 > x1) x0 = y0 = -5, x1 = y1 = 5;
  View v;
  v.scale = scale;
  v.x0 = x0 - 0.5;
  v.y1 = y1 + 0.5;
  v.width = int(std::ceil((x1 - x0 + 1.0) * scale));
  v.height = int(std::ceil((y1 - y0 + 1.0) * scale)) + 24;  // room for the caption
  return v;
}

}  // namespace

TraceFile ReadTrace(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw CommandFailed(fmt::format("{}: cannot read the trace", path.string()));
  return ParseTrace(in, path.string());
}

TraceFile ParseTrace(std::istream& in, const std::string& source) {
  TraceFile trace;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty()) continue;
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(line);
    } catch (const nlohmann::json::exception& e) {
      throw CommandFailed(fmt::format("{}:{}: not JSON: {}", source, number, e.what()));
    }
    if (number == 1) {
      for (const char* key : {"walls", "doors", "people", "rate_hz", "robot_radius"}) {
        if (!j.contains(key))
          throw CommandFailed(fmt::format("{}:1: trace header has no '{}'", source, key));
      }
      trace.header = std::move(j);
    } else {
      for (const char* key : {"t", "robot", "doors", "people"}) {
        if (!j.contains(key))
          throw CommandFailed(fmt::format("{}:{}: sample has no '{}'", source, number, key));
      }
      trace.samples.push_back(std::move(j));
    }
  }
  if (trace.samples.empty())
    throw CommandFailed(fmt::format("{}: the trace has no samples", source));
  return trace;
}

cv::Mat RenderTraceFrame(const TraceFile& trace, std::size_t index, double pixels_per_metre) {
  const View v = MakeView(trace, pixels_per_metre);
  cv::Mat image(v.height, v.width, CV_8UC3, cv::Scalar(250, 250, 250));
  // Under everything, the driver's latest costmap snapshot: people's personal space light
  // violet, inflation light orange, lethal cells (walls, leaves, people and obstacles as the
  // laser sees them) red.
  for (std::size_t k = index + 1; k-- > 0;) {
    const auto& s = trace.samples[k];
    if (!s.contains("costmap")) continue;
    const auto& c = s["costmap"];
    const double res = c.value("resolution", 0.05), ox = c["origin"][0], oy = c["origin"][1];
    const int width = c.value("width", 0);
    const auto draw = [&](const char* key, const cv::Scalar& colour) {
      if (!c.contains(key) || width <= 0) return;
      for (const auto& cell : c[key]) {
        const std::uint32_t i = cell.get<std::uint32_t>();
        const double x = ox + (i % width) * res, y = oy + (i / width) * res;
        cv::rectangle(image, v(x, y), v(x + res, y + res), colour, cv::FILLED);
      }
    };
    draw("personal", cv::Scalar(245, 215, 225));
    draw("inflated", cv::Scalar(200, 228, 255));
    draw("lethal", cv::Scalar(110, 120, 235));
    break;
  }
  for (const auto& w : trace.header.at("walls")) {
    const cv::RotatedRect rect(
        v(w[0].get<double>(), w[1].get<double>()),
        cv::Size2f(float(w[3].get<double>() * v.scale), float(w[4].get<double>() * v.scale)),
        float(-w[2].get<double>() * 180.0 / M_PI));
    cv::Point2f corners[4];
    rect.points(corners);
    std::vector<cv::Point> poly(corners, corners + 4);
    cv::fillConvexPoly(image, poly, cv::Scalar(70, 70, 70), cv::LINE_AA);
  }
  const auto& sample = trace.samples.at(index);
  const auto& doors = trace.header.at("doors");
  for (std::size_t i = 0; i < doors.size(); ++i) {
    const auto& d = doors[i];
    const double hx = d["hinge"][0], hy = d["hinge"][1], lx = d["latch"][0], ly = d["latch"][1];
    const double angle = sample["doors"][i][0].get<double>() * d["swing"].get<double>();
    const double dx = lx - hx, dy = ly - hy;
    const double ex = hx + std::cos(angle) * dx - std::sin(angle) * dy;
    const double ey = hy + std::sin(angle) * dx + std::cos(angle) * dy;
    cv::line(image, v(hx, hy), v(lx, ly), cv::Scalar(200, 200, 200), 1, cv::LINE_AA);  // threshold
    const bool glass = d.value("glass", false);
    cv::line(image, v(hx, hy), v(ex, ey),
             glass ? cv::Scalar(220, 180, 90) : cv::Scalar(40, 90, 150), 4, cv::LINE_AA);
  }
  // Paths so far: the robot in blue, people in orange.
  const std::size_t people = trace.header.at("people").size();
  for (std::size_t k = 1; k <= index; ++k) {
    const auto& a = trace.samples[k - 1];
    const auto& b = trace.samples[k];
    cv::line(image, v(a["robot"][0], a["robot"][1]), v(b["robot"][0], b["robot"][1]),
             cv::Scalar(200, 90, 30), 2, cv::LINE_AA);
    for (std::size_t p = 0; p < people && p < a["people"].size(); ++p) {
      cv::line(image, v(a["people"][p][0], a["people"][p][1]),
               v(b["people"][p][0], b["people"][p][1]), cv::Scalar(60, 150, 240), 1, cv::LINE_AA);
    }
  }
  // The driver's planned path (the brain's), if the trace has one.
  if (sample.contains("path") && sample["path"].is_array()) {
    const auto& path = sample["path"];
    for (std::size_t k = 1; k < path.size(); ++k) {
      cv::line(image, v(path[k - 1][0], path[k - 1][1]), v(path[k][0], path[k][1]),
               cv::Scalar(60, 180, 60), 2, cv::LINE_AA);
    }
  }
  for (std::size_t p = 0; p < people; ++p) {
    const auto& q = sample["people"][p];
    cv::circle(image, v(q[0], q[1]), int(0.25 * v.scale), cv::Scalar(30, 110, 230), cv::FILLED,
               cv::LINE_AA);
    // Velocity arrow: where the person will be in a second.
    if (index > 0 && p < trace.samples[index - 1]["people"].size()) {
      const auto& before = trace.samples[index - 1];
      const double dt = sample["t"].get<double>() - before["t"].get<double>();
      if (dt > 0) {
        const double vx = (q[0].get<double>() - before["people"][p][0].get<double>()) / dt;
        const double vy = (q[1].get<double>() - before["people"][p][1].get<double>()) / dt;
        if (std::hypot(vx, vy) > 0.1) {
          cv::arrowedLine(image, v(q[0], q[1]), v(q[0].get<double>() + vx, q[1].get<double>() + vy),
                          cv::Scalar(20, 80, 200), 2, cv::LINE_AA, 0, 0.2);
        }
      }
    }
    if (q.size() > 2 && q[2].is_string()) {
      cv::putText(image, q[2].get<std::string>(), v(q[0], q[1]) + cv::Point(8, -8),
                  cv::FONT_HERSHEY_SIMPLEX, 0.35, cv::Scalar(20, 80, 200), 1, cv::LINE_AA);
    }
  }
  if (sample.contains("payloads")) {
    for (const auto& q : sample["payloads"]) {
      const cv::Point c = v(q[0], q[1]);
      cv::rectangle(image, c - cv::Point(3, 3), c + cv::Point(3, 3), cv::Scalar(40, 170, 40),
                    cv::FILLED);
    }
  }
  const double rx = sample["robot"][0], ry = sample["robot"][1], yaw = sample["robot"][2];
  const double radius = trace.header["robot_radius"];
  cv::circle(image, v(rx, ry), int(radius * v.scale), cv::Scalar(180, 60, 20), cv::FILLED,
             cv::LINE_AA);
  cv::line(image, v(rx, ry), v(rx + radius * std::cos(yaw), ry + radius * std::sin(yaw)),
           cv::Scalar(255, 255, 255), 2, cv::LINE_AA);
  // The arm: base to palm, seen from above.
  if (sample.contains("hand") && sample["hand"].is_array() && sample["hand"].size() >= 2) {
    const cv::Point hand = v(sample["hand"][0], sample["hand"][1]);
    cv::line(image, v(rx, ry), hand, cv::Scalar(40, 40, 40), 3, cv::LINE_AA);
    cv::circle(image, hand, 4, cv::Scalar(40, 40, 40), cv::FILLED, cv::LINE_AA);
  }
  const std::string held = sample.contains("held") && sample["held"].is_string()
                               ? " holding " + sample["held"].get<std::string>()
                               : "";
  cv::putText(
      image,
      fmt::format("{}  seed {}  t = {:.1f} s{}", trace.header.value("scenario", std::string()),
                  trace.header.value("seed", 0), sample["t"].get<double>(), held),
      {6, v.height - 8}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(20, 20, 20), 1, cv::LINE_AA);
  if (sample.contains("label") && sample["label"].is_string()) {
    const std::string label = sample["label"].get<std::string>();
    cv::putText(image, "BT: " + (label.empty() ? std::string("-") : label), {6, 18},
                cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(20, 20, 20), 1, cv::LINE_AA);
  }
  return image;
}

void WriteTracePng(const TraceFile& trace, const std::filesystem::path& png) {
  if (!perception::WriteImageFile(png, RenderTraceFrame(trace, trace.samples.size() - 1))) {
    throw CommandFailed(fmt::format("cannot write '{}'", png.string()));
  }
}

void WriteTraceVideo(const TraceFile& trace, const std::filesystem::path& mp4, double speedup) {
  const double rate = trace.header.at("rate_hz").get<double>();
  const cv::Mat first = RenderTraceFrame(trace, 0);
  perception::VideoFileWriter writer(mp4, "mp4v", rate * speedup, first.size());
  if (!writer.opened()) {
    throw CommandFailed(fmt::format(
        "cannot open '{}' for MP4 video (OpenCV has no MP4 writer here)", mp4.string()));
  }
  for (std::size_t i = 0; i < trace.samples.size(); ++i)
    writer.Write(RenderTraceFrame(trace, i));
}

}  // namespace egress::apps
