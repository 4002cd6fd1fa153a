#pragma once
// mvflow's doors into oneTBB's scheduler: parallel_for and task_arena::execute, with the
// happens-before edges oneTBB guarantees told to ThreadSanitizer.
//
// oneTBB hands a task to another thread inside libtbb.so (spawn, steal, the end of a wait), which
// Debian builds without -fsanitize=thread, so TSan sees none of that synchronisation: every write
// made before a parallel_for and read in its body, or made in a body and read after it, would be
// reported as a race. In a build with TSan these wrappers state the guarantees (the caller's work
// before the call happens before every body; every body happens before the call returns) with
// __tsan_release/__tsan_acquire. They state only the edges oneTBB itself makes (the thread that
// creates or splits off a task before the thread that runs it, every body before the return), so
// two bodies that run side by side are still checked against each other. Without TSan they are
// the oneTBB calls themselves.
// engine/refine/iteration_graph.cpp does the same for the flow graph's edges.

#include <type_traits>
#include <utility>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#if defined(__SANITIZE_THREAD__)
#define MVFLOW_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define MVFLOW_TSAN 1
#endif
#endif

#ifdef MVFLOW_TSAN
#include <sanitizer/tsan_interface.h>
#endif

namespace mvflow::parallel {

//! Under TSan: what this thread did so far happens before whatever a later acquire(same) does.
inline void release([[maybe_unused]] const void* sync) {
#ifdef MVFLOW_TSAN
  __tsan_release(const_cast<void*>(sync));
#endif
}
//! Under TSan: what came before every release(same) happens before what this thread does next.
inline void acquire([[maybe_unused]] const void* sync) {
#ifdef MVFLOW_TSAN
  __tsan_acquire(const_cast<void*>(sync));
#endif
}

namespace detail {
//! Releases on \p sync (when there is one) as it goes out of scope, also by an exception.
struct ReleaseAtExit {
  const void* sync;
  ~ReleaseAtExit() {
    if (sync) release(sync);
  }
};
//! Acquires on \p sync as it goes out of scope, also by an exception.
struct AcquireAtExit {
  const void* sync;
  ~AcquireAtExit() { acquire(sync); }
};
}  // namespace detail

//! Under TSan, a function object that carries its creator's history to whichever thread calls it:
//! every construction or copy releases on the new object's own address and every call acquires
//! there first, so no field is read before the hand-off is known (oneTBB copies a body into
//! each task it splits off, on the thread that splits). A construction also acquires there first
//! and a call releases there last, for oneTBB reuses a finished task's memory for a new one. Each
//! call then releases on \p after.
template <typename Function>
class HandedOver {
 public:
  HandedOver(const Function& function, const void* after) {
    acquire(this);
    function_ = &function;
    after_ = after;
    release(this);
  }
  HandedOver(const HandedOver& other) {
    acquire(this);
    acquire(&other);
    function_ = other.function_;
    after_ = other.after_;
    release(this);
  }
  HandedOver& operator=(const HandedOver&) = delete;
  template <typename... Arguments>
  decltype(auto) operator()(Arguments&&... arguments) const {
    acquire(this);
    const detail::ReleaseAtExit done{after_}, reusable{this};
    return (*function_)(std::forward<Arguments>(arguments)...);
  }

 private:
  const Function* function_;  // set in the constructors, after acquire(this)
  const void* after_;
};

//! oneapi::tbb::parallel_for(range, body).
template <typename Range, typename Body>
void parallel_for(const Range& range, const Body& body) {
#ifdef MVFLOW_TSAN
  const char after = 0;
  oneapi::tbb::parallel_for(range, HandedOver<Body>(body, &after));
  acquire(&after);
#else
  oneapi::tbb::parallel_for(range, body);
#endif
}

//! oneapi::tbb::parallel_for(first, last, body): body(i) for every i in [first, last).
template <typename Index, typename Body>
void parallel_for(Index first, Index last, const Body& body) {
#ifdef MVFLOW_TSAN
  const char after = 0;
  oneapi::tbb::parallel_for(first, last, HandedOver<Body>(body, &after));
  acquire(&after);
#else
  oneapi::tbb::parallel_for(first, last, body);
#endif
}

//! arena.execute(function): the function may run on one of the arena's threads.
template <typename Function>
decltype(auto) execute(oneapi::tbb::task_arena& arena, Function&& function) {
#ifdef MVFLOW_TSAN
  const char after = 0;
  const detail::AcquireAtExit joined{&after};
  return arena.execute(HandedOver<std::remove_reference_t<Function>>(function, &after));
#else
  return arena.execute(std::forward<Function>(function));
#endif
}

}  // namespace mvflow::parallel
