#include "weft/viz/display.h"

#include <X11/Xlib.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

namespace weft::viz {
namespace {

// Xvfb normally answers within a second; a loaded 2-core machine may need several.
constexpr auto kStartTimeout = std::chrono::seconds(20);

struct DisplayState {
  bool ok = false;
  std::string reason;
};

pid_t g_xvfb_pid = -1;

// A server VTK can draw on: it answers and offers GLX (an ssh-forwarded display may not).
bool can_connect(const char* name) {
  if (name == nullptr || *name == '\0') return false;
  Display* display = XOpenDisplay(name);
  if (display == nullptr) return false;
  int opcode = 0;
  int event = 0;
  int error = 0;
  const bool glx = XQueryExtension(display, "GLX", &opcode, &event, &error) != 0;
  XCloseDisplay(display);
  return glx;
}

void stop_xvfb() {
  if (g_xvfb_pid <= 0) return;
  ::kill(g_xvfb_pid, SIGTERM);
  int status = 0;
  // Xvfb exits promptly on SIGTERM (removing its lock file and socket); do not wait forever.
  for (int i = 0; i < 200; ++i) {
    if (::waitpid(g_xvfb_pid, &status, WNOHANG) != 0) {
      g_xvfb_pid = -1;
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ::kill(g_xvfb_pid, SIGKILL);
  ::waitpid(g_xvfb_pid, &status, 0);
  g_xvfb_pid = -1;
}

std::string find_in_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::string dirs = path != nullptr && *path != '\0' ? path : "/usr/local/bin:/usr/bin:/bin";
  std::size_t start = 0;
  while (start <= dirs.size()) {
    const std::size_t end = dirs.find(':', start);
    const std::string dir = dirs.substr(start, end == std::string::npos ? std::string::npos : end - start);
    if (!dir.empty()) {
      std::string candidate = fmt::format("{}/{}", dir, program);
      if (::access(candidate.c_str(), X_OK) == 0) return candidate;
    }
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return {};
}

// The last non-empty line Xvfb wrote to its log: the usual explanation of a failed start.
std::string last_line_of(const std::string& file) {
  std::ifstream in(file);
  std::string line;
  std::string last;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  }
  return last;
}

DisplayState start_xvfb() {
  const std::string xvfb = find_in_path("Xvfb");
  if (xvfb.empty())
    return {false, "no X display ($DISPLAY unset or unreachable) and Xvfb is not installed (apt install xvfb)"};

  int ready[2];
  if (::pipe2(ready, O_CLOEXEC) != 0) return {false, fmt::format("cannot start Xvfb: pipe: {}", std::strerror(errno))};
  char log_template[] = "/tmp/weft-xvfb-XXXXXX";
  const int log_fd = ::mkostemp(log_template, O_CLOEXEC);
  const std::string log_path = log_fd >= 0 ? log_template : "";

  // -noreset: by default the server resets when its last client leaves; without this flag,
  // tests running in parallel saw VTK's connection refused right after our probe (VTK then
  // aborts the process), and with it they never did in 35 runs.
  // Everything the child needs is prepared before fork: only async-signal-safe calls after it.
  const std::string fd_arg = std::to_string(ready[1]);
  std::vector<std::string> args{xvfb,           "-displayfd", fd_arg, "-screen", "0",
                                "1280x1024x24", "-nolisten",  "tcp",  "-noreset"};
  std::vector<char*> argv;
  argv.reserve(args.size() + 1);
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  // The server dies with us if we are killed, but PR_SET_PDEATHSIG fires when the forking
  // *thread* ends, so it is only safe from the main thread.
  const bool main_thread = ::syscall(SYS_gettid) == ::getpid();
  const pid_t parent = ::getpid();

  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(ready[0]);
    ::close(ready[1]);
    if (log_fd >= 0) ::close(log_fd), ::unlink(log_path.c_str());
    return {false, fmt::format("cannot start Xvfb: fork: {}", std::strerror(errno))};
  }
  if (pid == 0) {
    // A session of its own: a terminal's Ctrl-C, `timeout` and `kill -- -PGID` signal weft's
    // process group, and a server killed there took the run's X connection with it while it
    // drew (Xlib then exits the process, or it crashes, with no unwinding: no interrupted-run
    // rollback). The server still ends with weft: SIGTERM at exit (stop_xvfb) or PDEATHSIG.
    ::setsid();
    if (main_thread) {
      ::prctl(PR_SET_PDEATHSIG, SIGTERM);
      if (::getppid() != parent) ::_exit(127);
    }
    const int devnull = ::open("/dev/null", O_RDWR);
    if (devnull >= 0) {
      ::dup2(devnull, 0);
      ::dup2(devnull, 1);
      ::dup2(log_fd >= 0 ? log_fd : devnull, 2);
    }
    // dup2 onto itself does not clear O_CLOEXEC, so clear it explicitly for the ready pipe.
    ::fcntl(ready[1], F_SETFD, 0);
    ::execv(xvfb.c_str(), argv.data());
    ::_exit(127);
  }
  ::close(ready[1]);
  if (log_fd >= 0) ::close(log_fd);

  auto fail_start = [&](const std::string& what) -> DisplayState {
    ::kill(pid, SIGKILL);
    int status = 0;
    ::waitpid(pid, &status, 0);
    ::close(ready[0]);
    const std::string detail = log_path.empty() ? "" : last_line_of(log_path);
    if (!log_path.empty()) ::unlink(log_path.c_str());
    return {false, detail.empty() ? fmt::format("Xvfb {}", what) : fmt::format("Xvfb {} ({})", what, detail)};
  };

  // Xvfb writes its display number to the fd once it listens for connections.
  std::string number;
  const auto deadline = std::chrono::steady_clock::now() + kStartTimeout;
  while (number.empty() || number.back() != '\n') {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
    if (left <= 0) return fail_start(fmt::format("did not start within {} s", kStartTimeout.count()));
    pollfd p{ready[0], POLLIN, 0};
    const int n = ::poll(&p, 1, static_cast<int>(left));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return fail_start(fmt::format("start failed: poll: {}", std::strerror(errno)));
    if (n == 0) continue;
    char buf[32];
    const ssize_t got = ::read(ready[0], buf, sizeof buf);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) return fail_start("exited during start-up");
    number.append(buf, static_cast<std::size_t>(got));
  }
  ::close(ready[0]);
  if (!log_path.empty()) ::unlink(log_path.c_str());
  while (!number.empty() && (number.back() == '\n' || number.back() == '\r')) number.pop_back();
  const std::string name = ":" + number;

  g_xvfb_pid = pid;
  std::atexit(stop_xvfb);
  // The server said it listens; confirm that a client gets through before handing it out.
  for (int attempt = 0; attempt < 100; ++attempt) {
    if (can_connect(name.c_str())) {
      ::setenv("DISPLAY", name.c_str(), 1);
      return {true, {}};
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  stop_xvfb();
  return {false, fmt::format("Xvfb started on {} but refuses connections", name)};
}

}  // namespace

bool ensure_display(std::string* why) {
  static std::once_flag once;
  static DisplayState state;
  std::call_once(once, [] {
    if (can_connect(std::getenv("DISPLAY"))) {
      state = {true, {}};
      return;
    }
    state = start_xvfb();
  });
  if (!state.ok && why != nullptr) *why = state.reason;
  return state.ok;
}

}  // namespace weft::viz
