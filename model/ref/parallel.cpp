#include "ref/parallel.h"

#include <exception>
#include <memory>
#include <thread>

#include <oneapi/tbb/global_control.h>
#include <oneapi/tbb/info.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

namespace oprt {

namespace {
int g_threads = 0;
std::unique_ptr<tbb::global_control> g_control;
}  // namespace

void set_thread_count(int threads) {
  g_threads = threads > 0 ? threads : 0;
  g_control = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                     static_cast<std::size_t>(thread_count()));
  // Start the pool's threads now, once per process, rather than inside the first frame.
  parallel_chunks(static_cast<std::size_t>(thread_count()), 1, [](std::size_t, std::size_t, std::size_t) {});
}

int thread_count() { return g_threads > 0 ? g_threads : tbb::info::default_concurrency(); }

void parallel_chunks(std::size_t n, std::size_t grain,
                     const std::function<void(std::size_t, std::size_t, std::size_t)>& body) {
  const std::size_t chunks = chunk_count(n, grain);
  if (chunks == 0) return;
  auto run = [&] {
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, chunks, 1),
        [&](const tbb::blocked_range<std::size_t>& r) {
          for (std::size_t c = r.begin(); c != r.end(); ++c) body(c, c * grain, std::min(n, (c + 1) * grain));
        },
        tbb::simple_partitioner());
  };
  // A SystemC thread runs on a small coroutine stack that the sanitizers and TBB's own
  // bookkeeping do not expect: hand the work to an ordinary thread and wait for it.
  std::exception_ptr error;
  std::thread worker([&] {
    try {
      run();
    } catch (...) {
      error = std::current_exception();
    }
  });
  worker.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace oprt
