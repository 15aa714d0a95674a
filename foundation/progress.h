// Progress reporting for long stages.
//
// Contract: a Progress is called from the orchestrating thread only (never
// from worker threads). The stderr implementation redraws one line per stage
// at most ~5 times a second and prints the stage time when the stage ends.
// A null/quiet Progress does nothing. Progress never changes results.
#pragma once
#include <chrono>
#include <string>

namespace vista {

class Progress {
public:
    virtual ~Progress() = default;
    virtual void begin(const std::string& stage) { (void)stage; }
    virtual void update(double fraction) { (void)fraction; }  // 0..1
    virtual void end() {}
};

class StderrProgress : public Progress {
public:
    explicit StderrProgress(bool tty);
    void begin(const std::string& stage) override;
    void update(double fraction) override;
    void end() override;

private:
    bool _tty;
    std::string _stage;
    std::chrono::steady_clock::time_point _start, _last;
};

}  // namespace vista
