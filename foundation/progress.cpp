#include "foundation/progress.h"

#include <cstdio>

namespace vista {

StderrProgress::StderrProgress(bool tty) : _tty(tty) {}

void StderrProgress::begin(const std::string& stage) {
    _stage = stage;
    _start = _last = std::chrono::steady_clock::now();
    std::fprintf(stderr, _tty ? "  %-12s ...\r" : "  %-12s ...\n", _stage.c_str());
    std::fflush(stderr);
}

void StderrProgress::update(double f) {
    auto now = std::chrono::steady_clock::now();
    if (now - _last < std::chrono::milliseconds(_tty ? 200 : 2000)) return;
    _last = now;
    double el = std::chrono::duration<double>(now - _start).count();
    double eta = f > 0.01 ? el * (1 - f) / f : 0;
    std::fprintf(stderr, _tty ? "  %-12s %5.1f%%  eta %.0fs   \r" : "  %-12s %5.1f%%  eta %.0fs\n", _stage.c_str(),
                 100 * f, eta);
    std::fflush(stderr);
}

void StderrProgress::end() {
    double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - _start).count();
    std::fprintf(stderr, "  %-12s done in %.2fs          \n", _stage.c_str(), el);
    std::fflush(stderr);
}

}  // namespace vista
