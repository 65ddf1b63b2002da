// Runs a function in a forked child with a wall-clock limit, so a test of third-party code that
// might hang (or of code run with fewer privileges) fails cleanly instead of blocking ctest.
#pragma once

#include <chrono>
#include <csignal>
#include <functional>
#include <poll.h>
#include <string>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace chaintube::hardening {

struct ChildOutcome
{
    bool finished = false; ///< exited on its own within the limit
    int exitCode = -1;     ///< its exit code when finished
    std::string message;   ///< what the child wrote (at most 64 KiB)
    double seconds = 0.0;  ///< wall time until it exited or was killed
};

/// Forks; the child runs `body`, which writes its result through `write` and returns an exit
/// code. The parent waits at most `limit`, then kills the child with SIGKILL.
inline ChildOutcome
runInChild(const std::function<int(const std::function<void(const std::string&)>&)>& body,
           std::chrono::milliseconds limit)
{
    int fds[2];
    ChildOutcome outcome;
    if (::pipe(fds) != 0) return outcome;
    const auto start = std::chrono::steady_clock::now();
    const pid_t pid = ::fork();
    if (pid == 0) {
        ::close(fds[0]);
        const auto write = [&](const std::string& text) {
            std::size_t done = 0;
            while (done < text.size()) {
                const ssize_t n = ::write(fds[1], text.data() + done, text.size() - done);
                if (n <= 0) break;
                done += static_cast<std::size_t>(n);
            }
        };
        int code = 99;
        try {
            code = body(write);
        } catch (...) {
            write("unexpected exception in the child");
        }
        ::_exit(code);
    }
    ::close(fds[1]);
    if (pid < 0) {
        ::close(fds[0]);
        return outcome;
    }
    int status = 0;
    bool exited = false;
    char chunk[4096];
    while (true) {
        const auto elapsed = std::chrono::steady_clock::now() - start;
        if (elapsed >= limit) break;
        pollfd descriptor{fds[0], POLLIN, 0};
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(limit - elapsed);
        if (::poll(&descriptor, 1, static_cast<int>(std::min<long long>(left.count(), 50))) > 0) {
            const ssize_t n = ::read(fds[0], chunk, sizeof chunk);
            if (n > 0 && outcome.message.size() < 65536)
                outcome.message.append(chunk, static_cast<std::size_t>(n));
        }
        if (::waitpid(pid, &status, WNOHANG) == pid) {
            exited = true;
            break;
        }
    }
    if (!exited) {
        ::kill(pid, SIGKILL);
        ::waitpid(pid, &status, 0);
    } else {
        ssize_t n;
        while ((n = ::read(fds[0], chunk, sizeof chunk)) > 0)
            if (outcome.message.size() < 65536)
                outcome.message.append(chunk, static_cast<std::size_t>(n));
    }
    ::close(fds[0]);
    outcome.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    outcome.finished = exited && WIFEXITED(status);
    if (outcome.finished) outcome.exitCode = WEXITSTATUS(status);
    return outcome;
}

} // namespace chaintube::hardening
