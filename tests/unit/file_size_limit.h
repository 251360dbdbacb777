#pragma once
/// @file
/// @brief A file size limit for tests of short writes: write(2) past it fails with EFBIG, as on a
/// full disk it fails with ENOSPC.

#include <csignal>

#include <sys/resource.h>

namespace weft::test {

/// While alive, files of this process past `bytes` fail to grow; SIGXFSZ is ignored meanwhile, as its
/// default action would kill the test.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    ::getrlimit(RLIMIT_FSIZE, &saved_);
    previous_ = std::signal(SIGXFSZ, SIG_IGN);
    rlimit limit = saved_;
    limit.rlim_cur = bytes;
    ::setrlimit(RLIMIT_FSIZE, &limit);
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &saved_);
    std::signal(SIGXFSZ, previous_);
  }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;

 private:
  rlimit saved_{};
  void (*previous_)(int) = nullptr;
};

}  // namespace weft::test
