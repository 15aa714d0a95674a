// Status and Result<T>: recoverable errors for bad external input.
//
// Contract: a Status is either ok() or carries a human-readable message that
// names the offending field, the value and the allowed range. Library code
// returns these; only the command-line `main` turns them into a message on
// stderr and exit code 2. Contract violations (programming errors) are
// VISTA_CHECK failures, which print file:line and abort.
#pragma once
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <utility>

namespace vista {

class Status {
public:
    Status() = default;
    static Status ok() { return Status(); }
    static Status error(std::string message) {
        Status s;
        s._failed = true;
        s._message = std::move(message);
        return s;
    }
    bool isOk() const { return !_failed; }
    explicit operator bool() const { return !_failed; }
    const std::string& message() const { return _message; }

private:
    bool _failed = false;
    std::string _message;
};

// Holds either a value or an error Status. Accessing value() of an error is a
// contract violation.
template <class T>
class Result {
public:
    Result(T value) : _value(std::move(value)) {}
    Result(Status status) : _status(std::move(status)) {
        if (_status.isOk()) {
            std::fprintf(stderr, "Result constructed from ok Status\n");
            std::abort();
        }
    }
    bool isOk() const { return _value.has_value(); }
    explicit operator bool() const { return isOk(); }
    const Status& status() const { return _status; }
    T& value() {
        if (!_value) {
            std::fprintf(stderr, "Result::value on error: %s\n", _status.message().c_str());
            std::abort();
        }
        return *_value;
    }
    const T& value() const { return const_cast<Result*>(this)->value(); }
    T* operator->() { return &value(); }
    T& operator*() { return value(); }

private:
    std::optional<T> _value;
    Status _status;
};

[[noreturn]] inline void checkFailed(const char* expr, const char* file, int line) {
    std::fprintf(stderr, "VISTA_CHECK failed: %s at %s:%d\n", expr, file, line);
    std::abort();
}

}  // namespace vista

#define VISTA_CHECK(cond)                                             \
    do {                                                              \
        if (!(cond)) ::vista::checkFailed(#cond, __FILE__, __LINE__); \
    } while (0)

// Propagates an error Status from an expression returning Status.
#define VISTA_RETURN_IF_ERROR(expr)            \
    do {                                       \
        ::vista::Status _vista_s = (expr);     \
        if (!_vista_s.isOk()) return _vista_s; \
    } while (0)
