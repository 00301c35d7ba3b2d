// Where the CLI was when it died or was interrupted. On a fatal signal (SIGSEGV, SIGABRT,
// SIGBUS, SIGFPE, SIGILL) a handler prints one line naming the command, the phase
// (start-up, frame N of a mode, exit) and the signal, using only async-signal-safe
// calls, then re-raises the signal so the exit status and core dump stay the default
// ones. SIGINT and SIGTERM end the process at once, except while a frame loop polls
// interruptRequested(): then they only set the flag, so the run can finish its files, and
// a second Ctrl-C kills the process at once.
#pragma once

#include <cstdint>

namespace dyncull::cli {

/// Installs the handlers (once, from main) and makes stdout line-buffered, so lines
/// printed before a crash are not lost in a buffer when stdout is a file or a pipe.
void installCrashReporter(const char* command);

/// The phase a crash line names: a string with static storage duration ("start-up",
/// "exit", ...). Not thread-safe against other setters; only the main thread calls it.
void setCrashPhase(const char* phase);
/// The phase is "frame `frame` of mode `mode`" (mode copied, at most 31 characters).
void setCrashFrame(std::uint64_t frame, const char* mode);

/// While `polled`, SIGINT and SIGTERM set the flag instead of ending the process.
void setInterruptPolled(bool polled);
/// True once SIGINT or SIGTERM arrived; frame loops stop at the next frame boundary.
bool interruptRequested();
/// The signal that set interruptRequested() (SIGINT or SIGTERM), 0 if none.
int interruptSignal();

}  // namespace dyncull::cli
