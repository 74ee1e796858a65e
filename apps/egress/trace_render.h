#pragma once
// Pictures of a twin run from its trace (JSON lines, see egress/twin/trace.h): a top-down frame
// per sample (walls, door leaves at their angles, people, the robot) and the paths so far.

#include <filesystem>
#include <istream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

namespace egress::apps {

struct TraceFile {
  nlohmann::json header;
  std::vector<nlohmann::json> samples;
};

/// Reads a trace. @throws CommandFailed naming the file and line of bad JSON or a missing field.
TraceFile ReadTrace(const std::filesystem::path& path);
/// The same from trace text; `source` names it in errors.
TraceFile ParseTrace(std::istream& in, const std::string& source);

/// The frame of sample `index` (with the robot's and people's paths up to it).
/// `pixels_per_metre` sets the scale.
cv::Mat RenderTraceFrame(const TraceFile& trace, std::size_t index, double pixels_per_metre = 40.0);

/// Writes the last frame as a PNG (or one frame per sample into an MP4 at the trace's rate).
/// @throws CommandFailed if the file cannot be written.
void WriteTracePng(const TraceFile& trace, const std::filesystem::path& png);
void WriteTraceVideo(const TraceFile& trace, const std::filesystem::path& mp4,
                     double speedup = 1.0);

}  // namespace egress::apps
