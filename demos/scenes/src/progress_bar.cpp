#include "dyncull/demos/progress_bar.hpp"

#include <algorithm>
#include <cstring>
#include <unistd.h>

namespace dyncull {

ProgressBar::ProgressBar(std::string label, double total, std::FILE* out)
    : label_(std::move(label)), total_(std::max(total, 1e-9)), out_(out), tty_(out && isatty(fileno(out)) != 0),
      start_(std::chrono::steady_clock::now()), lastDraw_(start_) {
    std::lock_guard<std::mutex> lock(mutex_);
    draw(true);
}

void ProgressBar::advance(double amount, std::string note) {
    std::lock_guard<std::mutex> lock(mutex_);
    note_ = std::move(note);
    done_ = std::min(total_, done_ + amount);
    draw(false);
}

void ProgressBar::restart(std::string label, double total) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!finished_) {
        done_ = total_;
        draw(true);
        if (tty_ && out_) std::fputc('\n', out_);
    }
    label_ = std::move(label);
    note_.clear();
    total_ = std::max(total, 1e-9);
    done_ = 0.0;
    finished_ = false;
    start_ = lastDraw_ = std::chrono::steady_clock::now();
    draw(true);
}

void ProgressBar::finish() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (finished_) return;
    // The last advance may have drawn the finished state already: do not repeat it.
    if (lastDrawnDone_ < total_) {
        done_ = total_;
        draw(true);
    }
    if (tty_ && out_) std::fputc('\n', out_);
    finished_ = true;
}

void ProgressBar::cancel() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (finished_) return;
    if (tty_ && out_) std::fputc('\n', out_);
    finished_ = true;
}

void ProgressBar::draw(bool force) {
    if (!out_) return;
    const auto now = std::chrono::steady_clock::now();
    const double sinceDraw = std::chrono::duration<double>(now - lastDraw_).count();
    // A TTY redraws ten times a second; a log gets a line every 5 s at most.
    if (!force && sinceDraw < (tty_ ? 0.1 : 5.0)) return;
    lastDraw_ = now;
    lastDrawnDone_ = done_;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double frac = std::clamp(done_ / total_, 0.0, 1.0);
    const double eta = frac > 1e-3 ? elapsed * (1.0 - frac) / frac : 0.0;
    char tail[96];
    if (frac >= 1.0) std::snprintf(tail, sizeof tail, "done in %.1f s", elapsed);
    else if (frac > 1e-3) std::snprintf(tail, sizeof tail, "ETA %.0f s", eta);
    else std::snprintf(tail, sizeof tail, "ETA --");
    if (!note_.empty()) {
        const std::size_t used = std::strlen(tail);
        std::snprintf(tail + used, sizeof tail - used, "  %s", note_.c_str());
    }
    if (tty_) {
        constexpr int kWidth = 30;
        const int filled = static_cast<int>(frac * kWidth);
        std::string bar(static_cast<std::size_t>(filled), '#');
        bar.resize(kWidth, '.');
        std::fprintf(out_, "\r%-28s [%s] %3.0f%%  %-40s", label_.c_str(), bar.c_str(), 100.0 * frac, tail);
    } else {
        std::fprintf(out_, "%s: %.0f%% %s\n", label_.c_str(), 100.0 * frac, tail);
    }
    std::fflush(out_);
}

}  // namespace dyncull
