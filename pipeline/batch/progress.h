// Progress of a batch on stderr: a live bar with frame count and ETA when
// stderr is a terminal, one plain line per frame otherwise (farm logs).
#pragma once

#include <chrono>
#include <string>

namespace hp {

class Progress {
  public:
    Progress(std::string label, size_t total);
    ~Progress();
    /// Marks one more unit done; `what` describes it ("frame 12").
    void advance(const std::string& what);
    /// Erases the bar (called before other log lines).
    void clearLine();

  private:
    void draw();
    std::string label_;
    size_t total_;
    size_t done_ = 0;
    bool tty_;
    bool drawn_ = false;
    std::chrono::steady_clock::time_point start_, last_;
};

/// "1m02s", "3.4s", "1h05m".
std::string formatDuration(double seconds);

}  // namespace hp
