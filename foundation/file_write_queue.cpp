// Atomic file writes on threads of their own (file_write_queue.h).
#include "foundation/file_write_queue.h"

#include <algorithm>

#include "foundation/atomic_file.h"

namespace vista {

FileWriteQueue::FileWriteQueue(int threads) {
    for (int i = 0; i < std::max(threads, 1); ++i) _threads.emplace_back([this] { run(); });
}

FileWriteQueue::~FileWriteQueue() {
    {
        std::unique_lock<std::mutex> lock(_mutex);
        _idle.wait(lock, [this] { return _files.empty() && _busy == 0; });
        _stop = true;
    }
    _work.notify_all();
    for (std::thread& t : _threads) t.join();
}

void FileWriteQueue::write(std::string path, std::string bytes) {
    {
        std::lock_guard<std::mutex> lock(_mutex);
        _files.emplace_back(std::move(path), std::move(bytes));
    }
    _work.notify_one();
}

Status FileWriteQueue::wait() {
    std::unique_lock<std::mutex> lock(_mutex);
    _idle.wait(lock, [this] { return _files.empty() && _busy == 0; });
    Status s = std::move(_first);
    _first = Status::ok();
    return s;
}

void FileWriteQueue::run() {
    std::unique_lock<std::mutex> lock(_mutex);
    for (;;) {
        _work.wait(lock, [this] { return _stop || !_files.empty(); });
        if (_files.empty()) return;  // stopping, nothing left
        std::pair<std::string, std::string> f = std::move(_files.front());
        _files.pop_front();
        ++_busy;
        lock.unlock();
        Status s = writeFileAtomic(f.first, f.second);
        f = {};  // free the bytes before taking the lock
        lock.lock();
        if (!s && _first) _first = std::move(s);
        if (--_busy == 0 && _files.empty()) _idle.notify_all();
    }
}

}  // namespace vista
