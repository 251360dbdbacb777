// Linked into every unit test when WEFT_TRAP_FP is on (preset `fp-trap`): enables traps for
// FE_INVALID, FE_DIVBYZERO and FE_OVERFLOW once GoogleTest starts running tests (not during
// test discovery), and on SIGFPE prints the running test and a backtrace before dying, so the
// trap names the expression that produced the NaN, infinity or overflow.
#include <cfenv>
#include <csignal>
#include <cstdio>
#include <cstring>

#include <execinfo.h>
#include <unistd.h>

#include <gtest/gtest.h>

namespace {

void on_fpe(int signal, siginfo_t* info, void*) {
  const char* what = "unknown";
  if (info->si_code == FPE_FLTINV) what = "invalid operation (NaN)";
  if (info->si_code == FPE_FLTDIV) what = "division by zero";
  if (info->si_code == FPE_FLTOVF) what = "overflow";
  const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
  std::fprintf(stderr, "\nWEFT_TRAP_FP: SIGFPE (%s) in test %s.%s\n", what, test ? test->test_suite_name() : "?",
               test ? test->name() : "?");
  void* frames[64];
  const int depth = backtrace(frames, 64);
  backtrace_symbols_fd(frames, depth, STDERR_FILENO);
  std::signal(signal, SIG_DFL);
  std::raise(signal);
}

class FpTrapEnvironment : public ::testing::Environment {
 public:
  void SetUp() override {
    struct sigaction action;
    std::memset(&action, 0, sizeof action);
    action.sa_sigaction = on_fpe;
    action.sa_flags = SA_SIGINFO;
    sigaction(SIGFPE, &action, nullptr);
    std::feclearexcept(FE_ALL_EXCEPT);
    feenableexcept(FE_INVALID | FE_DIVBYZERO | FE_OVERFLOW);
  }
  void TearDown() override { fedisableexcept(FE_ALL_EXCEPT); }
};

[[maybe_unused]] const auto* const kEnvironment = ::testing::AddGlobalTestEnvironment(new FpTrapEnvironment);

}  // namespace
