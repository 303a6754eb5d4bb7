// Core: reading a whole input file (file_read.hpp).
#include "core/file_read.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <memory>
#include <system_error>

namespace covrast::detail {

std::string size_text(std::uint64_t bytes) {
  if (bytes % (std::uint64_t(1) << 30) == 0) return std::to_string(bytes >> 30) + " GiB";
  if (bytes % (std::uint64_t(1) << 20) == 0) return std::to_string(bytes >> 20) + " MiB";
  return std::to_string(bytes) + " bytes";
}

namespace {

/// read_whole_file into a std::string or a byte vector.
template <class Buffer>
bool read_whole_file_into(const std::filesystem::path& path, Buffer& contents, std::string& error,
                          std::uint64_t max_bytes) {
  const auto system_error = [&](int code) {
    error = std::error_code(code, std::generic_category()).message();
    return false;
  };
  // A path string with an embedded NUL would quietly open its prefix.
  if (path.native().find('\0') != std::string::npos) {
    error = "the path contains a NUL byte";
    return false;
  }
  // O_NONBLOCK: opening a FIFO must not wait for a writer; fstat then refuses everything
  // that is not a regular file (FIFOs, devices such as /dev/zero, directories), checked on
  // the opened file itself so that nothing can swap it in between.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return system_error(errno);
  const std::unique_ptr<int, void (*)(int*)> closer(new int(fd), [](int* f) {
    ::close(*f);
    delete f;
  });
  struct stat info {};
  if (::fstat(fd, &info) != 0) return system_error(errno);
  if (S_ISDIR(info.st_mode)) return system_error(EISDIR);
  if (!S_ISREG(info.st_mode)) {
    error = "not a regular file";
    return false;
  }
  const auto size = static_cast<std::uint64_t>(info.st_size);
  if (size > max_bytes) {
    error = "file of " + std::to_string(size) + " bytes is larger than the " +
            size_text(max_bytes) + " limit";
    return false;
  }
  contents.assign(static_cast<std::size_t>(size), '\0');
  std::size_t done = 0;
  while (done < contents.size()) {
    const ssize_t got = ::read(fd, contents.data() + done, contents.size() - done);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) return system_error(errno);
    if (got == 0) break;  // the file shrank meanwhile: keep what is there
    done += static_cast<std::size_t>(got);
  }
  contents.resize(done);
  return true;
}

}  // namespace

std::string unreadable_kind(const std::filesystem::file_status& status) {
  if (std::filesystem::is_directory(status)) {
    return std::error_code(EISDIR, std::generic_category()).message();
  }
  if (!std::filesystem::exists(status) || std::filesystem::is_regular_file(status)) return "";
  return "not a regular file";
}

bool read_whole_file(const std::filesystem::path& path, std::string& contents, std::string& error,
                     std::uint64_t max_bytes) {
  return read_whole_file_into(path, contents, error, max_bytes);
}

bool read_whole_file(const std::filesystem::path& path, std::vector<unsigned char>& contents,
                     std::string& error, std::uint64_t max_bytes) {
  return read_whole_file_into(path, contents, error, max_bytes);
}

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace covrast::detail
