// FileWriteQueue: atomic file writes (writeFileAtomic) done by a few threads
// of their own, so that the caller's compute threads never wait on a disk.
//
// Contract: write(path, bytes) takes the bytes and returns at once; a queue
// thread later writes them with writeFileAtomic (temp file, fsync, rename),
// so each file appears whole or not at all, as a direct call would leave it.
// Files are taken in the order given; with more than one thread, several are
// written at once (their fsyncs overlap). wait() blocks until every file
// given so far is written (or failed) and returns the first error since the
// previous wait() (ok when none); the files after a failure are still
// written. The destructor waits for the files given and ends the threads.
//
// Why: an fsync blocks its thread for milliseconds; on a TBB worker it takes
// a core from the casts. The queue's threads are not TBB workers and spend
// their time blocked in the kernel, so a run's compute keeps its --threads.
//
// Thread safety: write() and wait() may be called from any thread.
#pragma once
#include <condition_variable>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "foundation/status.h"

namespace vista {

class FileWriteQueue {
public:
    // threads >= 1 writer threads (fewer are raised to 1).
    explicit FileWriteQueue(int threads = 4);
    ~FileWriteQueue();
    FileWriteQueue(const FileWriteQueue&) = delete;
    FileWriteQueue& operator=(const FileWriteQueue&) = delete;

    void write(std::string path, std::string bytes);
    Status wait();

private:
    void run();
    std::mutex _mutex;
    std::condition_variable _work, _idle;
    std::deque<std::pair<std::string, std::string>> _files;
    size_t _busy = 0;  // files taken and not yet written
    bool _stop = false;
    Status _first;  // the first error since the last wait()
    std::vector<std::thread> _threads;
};

}  // namespace vista
