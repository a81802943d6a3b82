// Ctrl-C, SIGHUP and SIGTERM during a render and during the write of its output (render.h).
#include <facet/render.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <signal.h>
#include <unistd.h>

namespace facet {

// ---------------------------------------------------------------------------------------------
// Interrupt handling

namespace {

std::atomic<bool> *g_interrupt_flag = nullptr;
volatile sig_atomic_t g_interrupt_signal = 0; ///< the first signal since the install
std::atomic<unsigned> g_signals_seen{0};      ///< bit `sig` per signal received
std::atomic<bool> g_deferring{false};
struct sigaction g_old_sigint, g_old_sighup, g_old_sigterm;
bool g_handler_installed = false;
static_assert(std::atomic<unsigned>::is_always_lock_free && std::atomic<bool>::is_always_lock_free,
              "the signal handler uses only lock-free atomics (async-signal-safe)");

extern "C" void facet_interrupt_handler(int sig) {
    const int saved_errno = errno;
    if (g_interrupt_signal == 0) g_interrupt_signal = sig;
    if (g_interrupt_flag) g_interrupt_flag->store(true);
    const unsigned bit = 1u << unsigned(sig);
    const bool repeated = (g_signals_seen.fetch_or(bit) & bit) != 0;
    if (!g_deferring.load()) {
        // While rendering, a second signal of the same kind takes the default action, so the
        // user can force quit: the render may take a while to reach a stop, and nothing but its
        // unfinished passes is lost (no output file is open yet).
        struct sigaction dfl;
        std::memset(&dfl, 0, sizeof(dfl));
        dfl.sa_handler = SIG_DFL;
        sigemptyset(&dfl.sa_mask);
        sigaction(sig, &dfl, nullptr);
    } else if (repeated) {
        // While the output is written, even a repeated signal is not fatal: the write is bounded
        // (encoding one image, writing, fsync, reading it back, renaming), force-quitting would
        // throw away the render the user waited for and leave the temporary file behind, and a
        // write stuck in the kernel (a dead network file system) would not run a handler anyway
        // (SIGKILL remains for that). Say why facet has not exited yet.
        static const char msg[] = "facet: still writing the image; exiting once it is complete\n";
        ssize_t ignored = ::write(STDERR_FILENO, msg, sizeof(msg) - 1);
        (void)ignored;
    }
    errno = saved_errno;
}

/// Points SIGINT, SIGHUP and SIGTERM at facet_interrupt_handler (the previous actions into
/// `old_*` when given).
void set_interrupt_actions(struct sigaction *old_int, struct sigaction *old_hup,
                           struct sigaction *old_term) {
    struct sigaction sa;
    std::memset(&sa, 0, sizeof(sa));
    sa.sa_handler = facet_interrupt_handler;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    sigaction(SIGINT, &sa, old_int);
    sigaction(SIGHUP, &sa, old_hup);
    sigaction(SIGTERM, &sa, old_term);
}

} // namespace

void install_interrupt_handler(std::atomic<bool> *flag) {
    if (g_handler_installed) uninstall_interrupt_handler();
    g_interrupt_flag = flag;
    g_interrupt_signal = 0;
    g_signals_seen = 0;
    g_deferring = false;
    set_interrupt_actions(&g_old_sigint, &g_old_sighup, &g_old_sigterm);
    g_handler_installed = true;
}

void defer_interrupts() {
    if (!g_handler_installed) return;
    g_deferring = true;
    // Back from the default action a first signal while rendering left for its kind.
    set_interrupt_actions(nullptr, nullptr, nullptr);
}

int interrupt_signal() { return int(g_interrupt_signal); }

const char *interrupt_signal_name(int sig) {
    switch (sig) {
    case SIGINT:
        return "SIGINT";
    case SIGHUP:
        return "SIGHUP";
    case SIGTERM:
        return "SIGTERM";
    default:
        return "a signal";
    }
}

void uninstall_interrupt_handler() {
    if (!g_handler_installed) return;
    sigaction(SIGINT, &g_old_sigint, nullptr);
    sigaction(SIGHUP, &g_old_sighup, nullptr);
    sigaction(SIGTERM, &g_old_sigterm, nullptr);
    g_interrupt_flag = nullptr;
    g_deferring = false;
    g_handler_installed = false;
}

} // namespace facet
