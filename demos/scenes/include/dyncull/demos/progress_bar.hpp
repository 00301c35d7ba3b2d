// Terminal progress for long scene generation and preprocessing: a redrawn bar with
// percentage and ETA when the stream is a TTY, else a plain line every few seconds (so
// logs of CI runs stay short). Thread-safe: worker threads report work done.
#pragma once

#include <chrono>
#include <cstdio>
#include <mutex>
#include <string>

namespace dyncull {

class ProgressBar {
public:
    /// Reports on `out` (borrowed; stderr by default), `total` > 0 units of work.
    ProgressBar(std::string label, double total, std::FILE* out = stderr);
    ~ProgressBar() { finish(); }
    ProgressBar(const ProgressBar&) = delete;
    ProgressBar& operator=(const ProgressBar&) = delete;

    /// Adds `amount` units of work done (any thread) and sets the short note shown after
    /// the ETA (e.g. "2495 ms/frame"; empty: none).
    void advance(double amount, std::string note = {});
    /// Starts a new phase: new label and total, progress back to zero, same stream.
    void restart(std::string label, double total);
    /// Prints the final state once (also done by the destructor).
    void finish();
    /// Ends the bar where it stands, for work stopped early (no "done" line).
    void cancel();

private:
    void draw(bool force);  // mutex held

    std::mutex mutex_;
    std::string label_;
    std::string note_;
    double total_, done_ = 0.0;
    double lastDrawnDone_ = -1.0;  // done_ when last drawn
    std::FILE* out_;
    bool tty_;
    bool finished_ = false;
    std::chrono::steady_clock::time_point start_, lastDraw_;
};

}  // namespace dyncull
