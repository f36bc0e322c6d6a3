// Work on several threads: the calling thread and worker threads kept from one call to the
// next. Every step's renderer (parallelRows) and step 04's batch tracer run on it.
//
// Why kept workers, and why the caller works too: starting threads for every call costs
// about as much as a short batch of rays takes, and a caller that only waits in join()
// leaves a core idle; so the caller works beside workers that wait for the next call.
#pragma once

#include <functional>

namespace boxes {

// The thread count a `threads` setting means: 0 (or less) is every hardware thread.
int resolveThreads(int threads);

// Runs task(thread) once on each of `threads` threads (0: all), thread 0 being the caller;
// returns when every one has returned. Workers take the caller's floating-point
// environment (rounding mode, enabled traps) as threads started for the call would. The
// first exception a task throws is rethrown here once all have returned; ending the other
// tasks early is the task's own business (they share whatever counter hands out work).
// A call made while the kept workers are busy (from another thread, or from inside a
// task) starts threads of its own.
void runOnThreads(int threads, const std::function<void(int thread)>& task);

}  // namespace boxes
