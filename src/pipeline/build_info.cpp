// What this build of covrast is and what it runs on (renderer.hpp): the line that golden
// images record and that test reports print, so that a mismatch says what rendered each side.
#include <covrast/renderer.hpp>
#include <covrast/tools.hpp>

#include <hwy/highway.h>
#include <hwy/targets.h>
#include <sys/utsname.h>

#include <fstream>
#include <string>

namespace covrast {
namespace {

std::string compiler_name() {
#if defined(__clang__)
  return std::string("clang ") + __clang_version__;
#elif defined(__GNUC__)
  return std::string("g++ ") + __VERSION__;
#else
  return "unknown compiler";
#endif
}

/// The processor's model name from /proc/cpuinfo (x86: "model name"; elsewhere the machine
/// name from uname, e.g. "aarch64").
std::string cpu_name() {
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);) {
    if (line.rfind("model name", 0) != 0) continue;
    const std::size_t colon = line.find(':');
    if (colon == std::string::npos) break;
    std::string name = line.substr(colon + 1);
    while (!name.empty() && name.front() == ' ') name.erase(name.begin());
    return name;
  }
  struct utsname machine {};
  return uname(&machine) == 0 ? std::string(machine.machine) : "unknown CPU";
}

/// The target the kernels dispatch to: the best one both compiled (HWY_TARGETS, the same in
/// every source of the library) and supported by this CPU, the lowest bit.
const char* simd_target() {
  const std::int64_t usable = HWY_TARGETS & hwy::SupportedTargets();
  return hwy::TargetName(usable & -usable);
}

std::string trimmed(std::string text) {
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

}  // namespace

BuildInfo build_info() {
  BuildInfo info;
  info.version = COVRAST_VERSION;
  info.compiler = trimmed(compiler_name());
  info.simd_target = simd_target();
  info.cpu = trimmed(cpu_name());
  return info;
}

}  // namespace covrast
