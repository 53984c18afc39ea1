// Threads for the functional work (oneTBB). Work is cut into chunks whose boundaries depend
// only on the amount of work, never on the number of threads, and every chunk writes its own
// results: the outputs are the same bytes for any thread count.
#pragma once

#include <cstddef>
#include <functional>

namespace oprt {

// How many threads the functional work may use; 0 means every core. Call once, before any
// parallel work (the oprt command does, from --threads).
void set_thread_count(int threads);
int thread_count();

// Calls body(chunk, begin, end) for every chunk [begin, end) of [0, n) cut every `grain`
// items, on the pool. Returns when every chunk is done; an exception thrown by a chunk is
// rethrown here. Safe to call from a SystemC process: the work runs on the pool's own
// threads, never on the caller's coroutine stack.
void parallel_chunks(std::size_t n, std::size_t grain,
                     const std::function<void(std::size_t chunk, std::size_t begin, std::size_t end)>& body);

inline std::size_t chunk_count(std::size_t n, std::size_t grain) { return (n + grain - 1) / grain; }

}  // namespace oprt
