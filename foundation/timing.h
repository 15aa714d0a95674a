// Timing: a monotonic stopwatch in milliseconds (steady_clock), for frame
// stages, set-up costs and progress. Never used to decide results: outputs
// do not depend on timing. Not thread-safe per instance.
#pragma once
#include <chrono>

namespace vista {

class Stopwatch {
public:
    Stopwatch() : _start(std::chrono::steady_clock::now()) {}
    void restart() { _start = std::chrono::steady_clock::now(); }
    // Milliseconds since construction or the last restart().
    double ms() const {
        return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - _start).count();
    }
    // ms(), then restart(): the time of one stage in a sequence.
    double lap() {
        const auto now = std::chrono::steady_clock::now();
        const double d = std::chrono::duration<double, std::milli>(now - _start).count();
        _start = now;
        return d;
    }

private:
    std::chrono::steady_clock::time_point _start;
};

}  // namespace vista
