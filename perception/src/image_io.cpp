#include "egress/perception/image_io.h"

#include <dlfcn.h>

#include <cstdlib>
#include <system_error>

#include "egress/hsr_interface/error.h"

namespace egress::perception {
namespace {

using internal::ImageIoModule;

constexpr const char* kModuleFile = "libegress_image_io.so";

// Where the module may be, in the order tried (see image_io.h).
std::vector<std::filesystem::path> ModuleCandidates() {
  // Named in the environment: that one alone (a module of another build is never taken
  // silently instead).
  if (const char* env = std::getenv("EGRESS_IMAGE_IO_MODULE"); env != nullptr && *env != '\0')
    return {std::filesystem::path(env)};
  std::vector<std::filesystem::path> candidates;
#ifdef EGRESS_IMAGE_IO_MODULE_PATH
  candidates.emplace_back(EGRESS_IMAGE_IO_MODULE_PATH);
#endif
  std::error_code error;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", error);
  if (!error) {
    candidates.push_back(exe.parent_path() / kModuleFile);
    candidates.push_back(exe.parent_path() / ".." / "lib" / kModuleFile);
  }
  return candidates;
}

const ImageIoModule* LoadModule() {
  std::string tried;
  for (const std::filesystem::path& path : ModuleCandidates()) {
    // RTLD_LOCAL: its OpenCV modules' symbols stay its own; never closed (its writers may live
    // to the end of the process).
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle == nullptr) {
      const char* why = dlerror();
      tried += StrCat("\n  ", path.string(), ": ", why != nullptr ? why : "cannot open");
      continue;
    }
    using Entry = const ImageIoModule* (*)();
    const auto entry = reinterpret_cast<Entry>(dlsym(handle, "egress_image_io_module"));
    const ImageIoModule* module = entry != nullptr ? entry() : nullptr;
    if (module != nullptr && module->version == internal::kImageIoModuleVersion) return module;
    tried += StrCat("\n  ", path.string(), ": not egress's image module of version ",
                    internal::kImageIoModuleVersion, " (a stale build?)");
  }
  throw LoadError(StrCat("cannot load egress's image module (", kModuleFile,
                         ", OpenCV's image and video files); set EGRESS_IMAGE_IO_MODULE to its "
                         "path. Tried:",
                         tried));
}

const ImageIoModule& Module() {
  static const ImageIoModule* const module = LoadModule();  // loaded once, thread-safe
  return *module;
}

}  // namespace

bool WriteImageFile(const std::filesystem::path& path, const cv::Mat& image) {
  return Module().write_file(path.string(), image);
}

bool EncodeImage(const std::string& extension, const cv::Mat& image,
                 std::vector<unsigned char>* out) {
  return Module().encode(extension, image, out);
}

cv::Mat DecodeGrayImage(const cv::Mat& encoded) {
  return Module().decode_gray(encoded);
}

VideoFileWriter::VideoFileWriter(const std::filesystem::path& path, const std::string& fourcc,
                                 double fps, cv::Size frame_size) {
  ThrowUnless(fourcc.size() == 4, "VideoFileWriter: the fourcc '", fourcc,
              "' must be four characters");
  // As cv::VideoWriter::fourcc packs it: the first character in the lowest byte.
  int code = 0;
  for (int i = 3; i >= 0; --i)
    code = (code << 8) | (static_cast<unsigned char>(fourcc[std::size_t(i)]) & 0xFF);
  writer_ = Module().open_video(path.string(), code, fps, frame_size);
}

VideoFileWriter::~VideoFileWriter() {
  if (writer_ != nullptr) Module().close_video(writer_);
}

void VideoFileWriter::Write(const cv::Mat& frame) {
  if (writer_ != nullptr) Module().write_video(writer_, frame);
}

}  // namespace egress::perception
