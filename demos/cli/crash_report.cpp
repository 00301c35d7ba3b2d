#include "crash_report.hpp"

#include <csignal>
#include <cstdio>
#include <cstring>
#include <initializer_list>
#include <unistd.h>

namespace dyncull::cli {
namespace {

// Read by the signal handlers: plain data, written only by the main thread.
const char* gCommand = "dyncull";
const char* volatile gPhase = "start-up";
volatile std::uint64_t gFrame = 0;
volatile bool gInFrame = false;
char gMode[32] = {};
volatile std::sig_atomic_t gInterrupt = 0;
volatile std::sig_atomic_t gPolled = 0;  // a frame loop polls interruptRequested()

// Appends text to buf (async-signal-safe: no allocation, no locale, no stdio).
void put(char* buf, std::size_t& n, std::size_t cap, const char* s) {
    while (*s && n + 1 < cap) buf[n++] = *s++;
}

void putNumber(char* buf, std::size_t& n, std::size_t cap, std::uint64_t v) {
    char digits[24];
    int k = 0;
    do {
        digits[k++] = static_cast<char>('0' + v % 10);
        v /= 10;
    } while (v && k < 24);
    while (k > 0 && n + 1 < cap) buf[n++] = digits[--k];
}

const char* signalName(int sig) {
    switch (sig) {
        case SIGSEGV: return "SIGSEGV";
        case SIGABRT: return "SIGABRT";
        case SIGBUS: return "SIGBUS";
        case SIGFPE: return "SIGFPE";
        case SIGILL: return "SIGILL";
        default: return "signal";
    }
}

void onFatalSignal(int sig) {
    char line[256];
    std::size_t n = 0;
    put(line, n, sizeof line, "\n");
    put(line, n, sizeof line, gCommand);
    put(line, n, sizeof line, ": fatal ");
    put(line, n, sizeof line, signalName(sig));
    put(line, n, sizeof line, " during ");
    if (gInFrame) {
        put(line, n, sizeof line, "frame ");
        putNumber(line, n, sizeof line, gFrame);
        put(line, n, sizeof line, " of mode ");
        put(line, n, sizeof line, gMode);
    } else {
        put(line, n, sizeof line, gPhase);
    }
    put(line, n, sizeof line, "\n");
    [[maybe_unused]] const ssize_t w = write(STDERR_FILENO, line, n);
    // SA_RESETHAND restored the default action: re-raise for the usual status and core.
    raise(sig);
}

void onInterrupt(int sig) {
    if (!gPolled) {  // nothing would notice the flag: the default action, at once
        signal(sig, SIG_DFL);
        raise(sig);
        return;
    }
    gInterrupt = sig;
}

}  // namespace

void installCrashReporter(const char* command) {
    gCommand = command;
    std::setvbuf(stdout, nullptr, _IOLBF, 0);
    // A stack overflow leaves no stack for the handler: give it its own.
    static char altStack[64 * 1024];
    stack_t ss{};
    ss.ss_sp = altStack;
    ss.ss_size = sizeof altStack;
    sigaltstack(&ss, nullptr);

    struct sigaction fatal{};
    fatal.sa_handler = onFatalSignal;
    fatal.sa_flags = SA_RESETHAND | SA_ONSTACK;
    sigemptyset(&fatal.sa_mask);
    for (int sig : {SIGSEGV, SIGABRT, SIGBUS, SIGFPE, SIGILL}) sigaction(sig, &fatal, nullptr);

    struct sigaction interrupt{};
    interrupt.sa_handler = onInterrupt;
    interrupt.sa_flags = SA_RESETHAND;  // the second Ctrl-C kills at once
    sigemptyset(&interrupt.sa_mask);
    for (int sig : {SIGINT, SIGTERM}) sigaction(sig, &interrupt, nullptr);
}

void setCrashPhase(const char* phase) {
    gInFrame = false;
    gPhase = phase;
}

void setCrashFrame(std::uint64_t frame, const char* mode) {
    std::strncpy(gMode, mode, sizeof gMode - 1);
    gFrame = frame;
    gInFrame = true;
}

void setInterruptPolled(bool polled) { gPolled = polled ? 1 : 0; }

bool interruptRequested() { return gInterrupt != 0; }

int interruptSignal() { return static_cast<int>(gInterrupt); }

}  // namespace dyncull::cli
