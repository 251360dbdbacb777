#include "interrupt.h"

#include <array>
#include <atomic>
#include <csignal>

#include <signal.h>

#include "weft/core/progress.h"
#include "weft/dist/distributed.h"

namespace weft::app {
namespace {

// A lock-free atomic is the one thing a signal handler may set besides volatile sig_atomic_t.
std::atomic<int> g_signal{0};
static_assert(std::atomic<int>::is_always_lock_free);

constexpr std::array<int, 2> kSignals{SIGINT, SIGTERM};

extern "C" void on_signal(int signal) {
  int none = 0;
  g_signal.compare_exchange_strong(none, signal, std::memory_order_relaxed);
}

}  // namespace

void catch_interrupts() {
  if (dist::size() > 1) return;
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  // One-shot: the handler resets itself to the default, so a second signal kills the process.
  action.sa_flags = SA_RESETHAND | SA_RESTART;
  for (const int signal : kSignals) ::sigaction(signal, &action, nullptr);
  set_stop_request(&g_signal);
}

int interrupt_signal() noexcept { return g_signal.load(std::memory_order_relaxed); }

void stop_if_interrupted() {
  if (interrupt_signal() != 0) throw Cancelled();
}

int interrupted_exit_code(int signal) noexcept { return 128 + signal; }

std::string_view interrupted_word(int signal) noexcept { return signal == SIGTERM ? "terminated" : "interrupted"; }

}  // namespace weft::app
