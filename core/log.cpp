#include "core/log.h"

#include <atomic>
#include <cstdio>
#include <mutex>

namespace hp {

namespace {
std::atomic<int> gLevel{static_cast<int>(LogLevel::Normal)};
std::mutex gMutex;
std::function<void()> gPreLine;
}  // namespace

void setLogLevel(LogLevel level) { gLevel = static_cast<int>(level); }
LogLevel logLevel() { return static_cast<LogLevel>(gLevel.load()); }

void logLine(LogLevel level, const std::string& line) {
    if (static_cast<int>(level) > gLevel.load()) return;
    std::lock_guard<std::mutex> lock(gMutex);
    if (gPreLine) gPreLine();
    std::fputs(line.c_str(), stderr);
    std::fputc('\n', stderr);
    std::fflush(stderr);
}

void setLogPreLineHook(std::function<void()> hook) {
    std::lock_guard<std::mutex> lock(gMutex);
    gPreLine = std::move(hook);
}

}  // namespace hp
