#pragma once
// Cancels a refinement from a thread of its own while an iteration is in the middle of its
// blocks, and counts the blocks that still ran after the flag was set: the cancel latency in
// blocks, not in seconds, so a loaded machine cannot make it flaky.

#include <atomic>
#include <cstddef>
#include <functional>
#include <semaphore>
#include <thread>

namespace mvflow::test {

class CancelProbe {
 public:
  //! When the engine reports its \p at-th block, that engine thread waits until the probe's own
  //! thread has called \p cancel: the flag is set while the iteration runs (the other engine
  //! threads go on), from a thread that is not the engine's.
  CancelProbe(std::size_t at, std::function<void()> cancel)
      : at_(at), cancel_(std::move(cancel)), thread_([this] { cancel_when_reached(); }) {}
  ~CancelProbe() { finish(); }
  CancelProbe(const CancelProbe&) = delete;
  CancelProbe& operator=(const CancelProbe&) = delete;

  //! For RefineControl::on_block or JobSpec::on_block; the probe must outlive the run.
  std::function<void(std::size_t)> hook() {
    return [this](std::size_t) {
      if (++reported_ != at_) return;
      reached_.release();
      cancelled_.acquire();
    };
  }
  //! Joins the probe's thread; call when the run has returned.
  void finish() {
    if (!thread_.joinable()) return;
    reached_.release();  // the run may have ended before the at-th block
    thread_.join();
  }
  bool fired() const { return fired_; }
  //! Blocks reported in all.
  std::size_t reported() const { return reported_; }
  //! Blocks reported after the flag was set: those that had passed the cancel check before it
  //! (running on the other threads then), and any that missed the flag.
  std::size_t after_cancel() const { return reported_ - at_cancel_; }

 private:
  void cancel_when_reached() {
    reached_.acquire();
    if (reported_ < at_) return;  // finish() without the run getting there
    cancel_();
    at_cancel_ = reported_.load();  // after the flag: a block counted later ran after it was set
    fired_ = true;
    cancelled_.release();
  }

  const std::size_t at_;
  std::function<void()> cancel_;
  std::atomic<std::size_t> reported_{0};
  std::size_t at_cancel_ = 0;
  std::atomic<bool> fired_{false};
  std::binary_semaphore reached_{0}, cancelled_{0};
  std::thread thread_;  // last: starts after every other member exists
};

}  // namespace mvflow::test
