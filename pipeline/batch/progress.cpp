#include "pipeline/batch/progress.h"

#include "core/log.h"

#include <cstdio>
#include <unistd.h>

namespace hp {

std::string formatDuration(double s) {
    char buf[32];
    if (s < 60) std::snprintf(buf, sizeof buf, "%.1fs", s);
    else if (s < 3600) std::snprintf(buf, sizeof buf, "%dm%02ds", int(s) / 60, int(s) % 60);
    else std::snprintf(buf, sizeof buf, "%dh%02dm", int(s) / 3600, (int(s) % 3600) / 60);
    return buf;
}

Progress::Progress(std::string label, size_t total)
    : label_(std::move(label)), total_(total), tty_(::isatty(STDERR_FILENO) && logLevel() != LogLevel::Quiet),
      start_(std::chrono::steady_clock::now()), last_(start_) {
    if (tty_) {
        setLogPreLineHook([this] { clearLine(); });
        draw();
    }
}

Progress::~Progress() {
    if (tty_) {
        setLogPreLineHook(nullptr);
        clearLine();
    }
}

void Progress::clearLine() {
    if (drawn_) std::fputs("\r\033[K", stderr), drawn_ = false;
}

void Progress::advance(const std::string& what) {
    ++done_;
    const auto now = std::chrono::steady_clock::now();
    const double took = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    if (tty_) {
        draw();
    } else {
        logInfo(label_, " ", what, " (", done_, "/", total_, ") ", formatDuration(took));
    }
}

void Progress::draw() {
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const int width = 30;
    const int filled = total_ ? int(width * done_ / total_) : width;
    std::string bar(filled, '#');
    bar.resize(width, '.');
    std::string eta = "--";
    if (done_ > 0 && done_ < total_) eta = formatDuration(elapsed / done_ * (total_ - done_));
    else if (done_ == total_) eta = "done";
    std::fprintf(stderr, "\r\033[K%s [%s] %zu/%zu  elapsed %s  ETA %s", label_.c_str(), bar.c_str(), done_, total_,
                 formatDuration(elapsed).c_str(), eta.c_str());
    std::fflush(stderr);
    drawn_ = true;
}

}  // namespace hp
