#include "interrupt.h"

#include <atomic>
#include <csignal>

#include <signal.h>

#include "weft/core/progress.h"
#include "weft/dist/distributed.h"

namespace weft::app {
namespace {

// A lock-free atomic is the one thing a signal handler may set besides volatile sig_atomic_t.
std::atomic<bool> g_requested{false};
static_assert(std::atomic<bool>::is_always_lock_free);

struct sigaction g_previous {};
bool g_installed = false;

extern "C" void on_sigint(int /*signal*/) { g_requested.store(true, std::memory_order_relaxed); }

}  // namespace

InterruptGuard::InterruptGuard() {
  if (dist::size() > 1) return;
  struct sigaction action {};
  action.sa_handler = on_sigint;
  sigemptyset(&action.sa_mask);
  // One-shot: the handler resets itself to the default, so a second Ctrl-C kills the process.
  action.sa_flags = SA_RESETHAND | SA_RESTART;
  g_installed = ::sigaction(SIGINT, &action, &g_previous) == 0;
}

InterruptGuard::~InterruptGuard() {
  if (g_installed) ::sigaction(SIGINT, &g_previous, nullptr);
  g_installed = false;
}

bool interrupt_requested() noexcept { return g_requested.load(std::memory_order_relaxed); }

void stop_if_interrupted() {
  if (interrupt_requested()) throw Cancelled();
}

}  // namespace weft::app
