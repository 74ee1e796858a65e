// egress: command line of the HSR evacuation-assistance system.

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>

#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "commands.h"
#include "egress/ros2/asan_options.h"  // the program links Fast DDS

namespace {

// [bytes] The main heap is grown by this much at once and given transparent huge pages.
constexpr std::size_t kHugePageHeapBytes = std::size_t{256} << 20;
constexpr std::uintptr_t kHugePageBytes = std::uintptr_t{2} << 20;
constexpr int kHeapBlockMaxBytes = 32 << 20;

// Start-up spent most of its wall time taking page faults on fresh heap: libsdformat clones its
// whole element description for every element it reads (clinic.sdf, 22 kB: ~130 MB touched,
// 34,000 faults, over half of a one-minute crowd run's start-up on a VM). Grown at once and
// advised for transparent huge pages (where the kernel gives them on advice), the heap takes one
// fault per 2 MB instead of per 4 kB; kept (not trimmed back), it is not faulted in again. The
// memory is virtual until touched. Nothing else changes: where the kernel gives no huge pages,
// the advice is ignored.
// Fast bins are off as well: the ~100 MB of small blocks libsdformat frees sat in them, and the
// first large allocation after (a file stream's buffer) consolidated them all, 55 ms of a
// 0.43 s start-up; freed straight into the ordinary bins (the thread cache still serves small
// blocks first), start-up took 0.37 s and the crowd run no longer.
void GrowHeapWithHugePages() {
  // Blocks up to 32 MB (glibc's largest threshold) from the heap, not mmap'd one by one (each
  // faulted in again whenever made); the heap grown by the pad at its next growth, and never
  // trimmed by less than twice that.
  if (mallopt(M_MMAP_THRESHOLD, kHeapBlockMaxBytes) != 1 ||
      mallopt(M_TOP_PAD, int(kHugePageHeapBytes)) != 1 ||
      mallopt(M_TRIM_THRESHOLD, int(2 * kHugePageHeapBytes)) != 1 || mallopt(M_MXFAST, 0) != 1)
    return;
  const auto begin = reinterpret_cast<std::uintptr_t>(sbrk(0));
  // A block larger than what the heap has free grows it (volatile: a malloc freed unused is
  // otherwise left out by the compiler).
  void* volatile block = std::malloc(std::size_t{kHeapBlockMaxBytes} / 2);
  std::free(block);
  const auto end = reinterpret_cast<std::uintptr_t>(sbrk(0));
  const std::uintptr_t from = (begin + kHugePageBytes - 1) & ~(kHugePageBytes - 1);
  const std::uintptr_t to = end & ~(kHugePageBytes - 1);
  if (to > from) madvise(reinterpret_cast<void*>(from), to - from, MADV_HUGEPAGE);
  mallopt(M_TOP_PAD, 0);  // back to growing as needed (the advised range stays)
}

}  // namespace

int main(int argc, char** argv) {
  GrowHeapWithHugePages();
  CLI::App app{
      "egress: an HSR robot brain that opens ADA doors ahead of evacuees, yields to people and "
      "fetches rescue equipment, run against a Bullet digital twin or the real robot.",
      "egress"};
  app.require_subcommand(0, 1);
  app.set_version_flag("-V,--version", egress::apps::VersionText,
                       "Print the egress version and the library versions it was built with");

  egress::apps::AddModelCommand(app);
  egress::apps::AddBtCommand(app);
  egress::apps::AddCostmapCommand(app);
  egress::apps::AddPlanCommand(app);
  egress::apps::AddBenchCommand(app);
  egress::apps::AddSimCommand(app);
  egress::apps::AddEvacCommand(app);
  egress::apps::AddRos2Commands(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const egress::apps::CommandFailed& e) {
    if (*e.what() != '\0') std::fprintf(stderr, "egress: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "egress: error: %s\n", e.what());
    return 1;
  }
  if (argc == 1) {
    std::fputs(app.help().c_str(), stdout);
  }
  return 0;
}
