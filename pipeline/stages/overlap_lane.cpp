#include "pipeline/stages/overlap_lane.h"

#include <utility>

namespace hp {

LaneFrame::LaneFrame(const FrameData& source) : data(source) {
    if (source.strands) {
        strands = *source.strands;
        data.strands = &strands;
    }
    if (source.head) {
        head = *source.head;
        data.head = &head;
    }
    data.simulation = nullptr;
    data.guides = nullptr;
}

OverlapLane::OverlapLane() : thread_([this] { loop(); }) {}

OverlapLane::~OverlapLane() {
    {
        std::unique_lock<std::mutex> lock(mutex_);
        waitIdle(lock);
        stop_ = true;
    }
    changed_.notify_all();
    thread_.join();
}

void OverlapLane::waitIdle(std::unique_lock<std::mutex>& lock) {
    changed_.wait(lock, [this] { return !job_; });
}

void OverlapLane::post(std::function<void()> job) {
    {
        std::unique_lock<std::mutex> lock(mutex_);
        waitIdle(lock);
        if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
        job_ = std::move(job);
    }
    changed_.notify_all();
}

void OverlapLane::drain() {
    std::unique_lock<std::mutex> lock(mutex_);
    waitIdle(lock);
    if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
}

void OverlapLane::loop() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
        changed_.wait(lock, [this] { return stop_ || job_; });
        if (!job_) return;  // stop_ and nothing left
        lock.unlock();
        std::exception_ptr error;
        try {
            job_();
        } catch (...) {
            error = std::current_exception();
        }
        lock.lock();
        if (error && !error_) error_ = error;
        job_ = nullptr;
        changed_.notify_all();
    }
}

}  // namespace hp
