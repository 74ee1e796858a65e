#include "egress/twin/trace.h"

#include <cstdio>
#include <fstream>

#include "egress/hsr_interface/error.h"

namespace egress::twin {
namespace {

std::string Fixed(double v, int digits = 4) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", digits, v);
  return buf;
}

}  // namespace

std::string JsonEscape(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof(buf), "\\u%04x", c);
          out += buf;
        } else {
          out += c;
        }
    }
  }
  return out;
}

TraceRecorder::TraceRecorder(double rate_hz) : period_(1.0 / rate_hz) {
  ThrowUnless(rate_hz > 0, "trace: rate must be positive");
}

void TraceRecorder::Observe(const TwinWorld& world, const TraceAnnotation* annotation) {
  // Built with += only: GCC 12 warns falsely (-Wrestrict) on "literal" + std::string.
  auto quoted = [](std::string* out, const std::string& text) {
    *out += '"';
    *out += JsonEscape(text);
    *out += '"';
  };
  if (header_.empty()) {
    // The header carries the floor plan (wall rectangles and doors), so a trace renders alone.
    std::string h = "{\"scenario\":";
    quoted(&h, world.scenario().name);
    h += ",\"seed\":";
    h += std::to_string(world.seed());
    h += ",\"rate_hz\":";
    h += Fixed(1.0 / period_, 2);
    h += ",\"robot_radius\":";
    h += Fixed(world.robot_radius(), 3);
    h += ",\"walls\":[";
    bool first = true;
    auto add_footprint = [&](const FloorFootprint& f) {
      if (!first) h += ',';
      first = false;
      h += '[';
      h += Fixed(f.X_WF.x);
      h += ',';
      h += Fixed(f.X_WF.y);
      h += ',';
      h += Fixed(f.X_WF.yaw);
      h += ',';
      h += Fixed(f.size.x());
      h += ',';
      h += Fixed(f.size.y());
      h += ']';
    };
    for (const auto& f : CalcFloorFootprints(world.world()))
      add_footprint(f);
    for (const auto& s : world.scenario().obstacles) {
      if (const auto f = CalcFloorFootprint(s)) add_footprint(*f);
    }
    h += "],\"doors\":[";
    for (std::size_t i = 0; i < world.door_count(); ++i) {
      const DoorDescription& d = world.door(i);
      const Eigen::Vector3d edge = d.CalcFreeEdge(0.0);
      if (i) h += ',';
      h += "{\"name\":";
      quoted(&h, d.name);
      h += ",\"hinge\":[";
      h += Fixed(d.p_WH.x());
      h += ',';
      h += Fixed(d.p_WH.y());
      h += "],\"latch\":[";
      h += Fixed(edge.x());
      h += ',';
      h += Fixed(edge.y());
      h += "],\"swing\":";
      h += Fixed(d.open_sign * (d.axis_W.z() > 0 ? 1.0 : -1.0), 0);
      h += ",\"glass\":";
      h += world.door_is_glass(i) ? "true" : "false";
      h += '}';
    }
    h += "],\"people\":[";
    for (std::size_t i = 0; i < world.people().size(); ++i) {
      if (i) h += ',';
      quoted(&h, world.people()[i].name);
    }
    h += "],\"payloads\":[";
    const auto payloads = world.payload_names();
    for (std::size_t i = 0; i < payloads.size(); ++i) {
      if (i) h += ',';
      quoted(&h, payloads[i]);
    }
    h += "]}";
    header_ = std::move(h);
  }
  if (world.time() + 1e-9 < next_) return;
  next_ += period_;
  const Pose2 X_WB = world.robot_pose();
  std::string s = "{\"t\":";
  s += Fixed(world.time(), 3);
  s += ",\"robot\":[";
  s += Fixed(X_WB.x);
  s += ',';
  s += Fixed(X_WB.y);
  s += ',';
  s += Fixed(X_WB.yaw);
  s += "],\"doors\":[";
  for (std::size_t i = 0; i < world.door_count(); ++i) {
    if (i) s += ',';
    s += '[';
    s += Fixed(world.door_angle(i));
    s += ',';
    quoted(&s, std::string(ToString(world.door_phase(i))));
    s += ']';
  }
  s += "],\"people\":[";
  for (std::size_t i = 0; i < world.people().size(); ++i) {
    const auto& p = world.people()[i];
    if (i) s += ',';
    s += '[';
    s += Fixed(p.position.x());
    s += ',';
    s += Fixed(p.position.y());
    s += ',';
    quoted(&s, std::string(ToString(p.phase)));
    s += ']';
  }
  s += "],\"payloads\":[";
  const auto names = world.payload_names();
  for (std::size_t i = 0; i < names.size(); ++i) {
    const Eigen::Vector3d p = world.payload_pose(names[i]).translation();
    if (i) s += ',';
    s += '[';
    s += Fixed(p.x());
    s += ',';
    s += Fixed(p.y());
    s += ',';
    s += Fixed(p.z());
    s += ']';
  }
  // The arm as the palm's position (a line from the base in the video).
  const Eigen::Vector3d p_WG = world.palm_pose().translation();
  s += "],\"hand\":[" + Fixed(p_WG.x()) + ',' + Fixed(p_WG.y()) + ',' + Fixed(p_WG.z());
  s += "],\"held\":";
  if (const auto held = world.held_payload()) {
    quoted(&s, *held);
  } else {
    s += "null";
  }
  s += ",\"events\":[";
  const auto& events = world.events();
  for (std::size_t i = events_seen_; i < events.size(); ++i) {
    const auto& e = events[i];
    if (i > events_seen_) s += ',';
    s += "{\"t\":";
    s += Fixed(e.t, 3);
    s += ",\"kind\":";
    quoted(&s, e.kind);
    s += ",\"subject\":";
    quoted(&s, e.subject);
    s += ",\"detail\":";
    quoted(&s, e.detail);
    s += '}';
  }
  events_seen_ = events.size();
  s += ']';
  if (annotation != nullptr) {
    s += ",\"label\":";
    quoted(&s, annotation->label);
    s += ",\"path\":[";
    for (std::size_t i = 0; i < annotation->path.size(); ++i) {
      if (i) s += ',';
      s += '[';
      s += Fixed(annotation->path[i].x());
      s += ',';
      s += Fixed(annotation->path[i].y());
      s += ']';
    }
    s += ']';
    if (const auto& g = annotation->costmap) {
      s += ",\"costmap\":{\"origin\":[" + Fixed(g->origin.x()) + ',' + Fixed(g->origin.y()) +
           "],\"resolution\":" + Fixed(g->resolution) + ",\"width\":" + std::to_string(g->width) +
           ",\"height\":" + std::to_string(g->height);
      const auto cells = [&s](const char* key, const std::vector<std::uint32_t>& indices) {
        s += ",\"";
        s += key;
        s += "\":[";
        for (std::size_t i = 0; i < indices.size(); ++i) {
          if (i) s += ',';
          s += std::to_string(indices[i]);
        }
        s += ']';
      };
      cells("inflated", g->inflated);
      cells("lethal", g->lethal);
      if (!g->personal.empty()) cells("personal", g->personal);
      s += '}';
    }
  }
  s += '}';
  samples_.push_back(std::move(s));
}

std::string TraceRecorder::ToJsonLines() const {
  std::string out = header_ + "\n";
  for (const auto& s : samples_)
    out += s + "\n";
  return out;
}

void TraceRecorder::Write(const std::filesystem::path& path) const {
  std::ofstream out(path);
  out << ToJsonLines();
  if (!out) throw LoadError(StrCat(path.string(), ": cannot write the trace"));
}

std::uint64_t TraceRecorder::Hash() const {
  std::uint64_t h = 1469598103934665603ull;
  for (const char c : ToJsonLines()) {
    h ^= static_cast<unsigned char>(c);
    h *= 1099511628211ull;
  }
  return h;
}

}  // namespace egress::twin
