#include "pipeline/batch/child_process.h"

#include "core/errors.h"

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <map>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace fs = std::filesystem;

namespace hp {

std::string ChildResult::describe() const {
    if (!error.empty()) return error;
    if (signal) return cat("killed by signal ", signal, " (", ::strsignal(signal), ")");
    return cat("exit code ", exitCode);
}

namespace {

/// A started child: its pid and, for piped output, the read end and the
/// partial line received so far.
struct Running {
    size_t task = 0;
    pid_t pid = -1;
    int fd = -1;
    std::string partial;
};

/// The environment for a child: ours with `extra` added or replacing.
std::vector<std::string> childEnvironment(const std::vector<std::string>& extra) {
    std::map<std::string, std::string> vars;
    std::vector<std::string> order;
    auto put = [&](const std::string& entry) {
        const std::string name = entry.substr(0, entry.find('='));
        if (!vars.count(name)) order.push_back(name);
        vars[name] = entry;
    };
    for (char** e = environ; e && *e; ++e) put(*e);
    for (const std::string& e : extra) put(e);
    std::vector<std::string> out;
    for (const std::string& name : order) out.push_back(vars[name]);
    return out;
}

std::vector<char*> pointers(std::vector<std::string>& strings) {
    std::vector<char*> p;
    for (std::string& s : strings) p.push_back(s.data());
    p.push_back(nullptr);
    return p;
}

/// Starts a task with stdout and stderr on `outFd`. Only async-signal-safe
/// calls happen between fork and exec (the parent may have threads).
pid_t spawn(const ChildTask& task, int outFd, std::string& error) {
    std::vector<std::string> args = task.argv;
    std::vector<std::string> env = childEnvironment(task.env);
    std::vector<char*> argv = pointers(args), envp = pointers(env);
    const int devNull = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
    const pid_t parent = ::getpid();
    const pid_t pid = ::fork();
    if (pid < 0) {
        error = cat("cannot start ", task.argv[0], ": ", std::strerror(errno));
        if (devNull >= 0) ::close(devNull);
        return -1;
    }
    if (pid == 0) {
        // The child ends when the batch that started it ends.
        ::prctl(PR_SET_PDEATHSIG, SIGTERM);
        if (::getppid() != parent) ::_exit(127);
        if (devNull >= 0) ::dup2(devNull, 0);
        ::dup2(outFd, 1);
        ::dup2(outFd, 2);
        ::execve(argv[0], argv.data(), envp.data());
        const char* msg = "hairpipe: cannot execute child process: ";
        ssize_t ignored = ::write(2, msg, std::strlen(msg));
        ignored = ::write(2, argv[0], std::strlen(argv[0]));
        ignored = ::write(2, "\n", 1);
        (void)ignored;
        ::_exit(127);
    }
    if (devNull >= 0) ::close(devNull);
    return pid;
}

ChildResult resultOf(int status) {
    ChildResult r;
    if (WIFEXITED(status)) r.exitCode = WEXITSTATUS(status);
    else if (WIFSIGNALED(status)) r.signal = WTERMSIG(status);
    return r;
}

/// Reads what is available; hands complete lines to onLine. Returns false at EOF.
bool drain(Running& r, const std::function<void(size_t, const std::string&)>& onLine) {
    char buf[4096];
    for (;;) {
        const ssize_t n = ::read(r.fd, buf, sizeof buf);
        if (n > 0) {
            r.partial.append(buf, size_t(n));
            size_t start = 0, nl;
            while ((nl = r.partial.find('\n', start)) != std::string::npos) {
                if (onLine) onLine(r.task, r.partial.substr(start, nl - start));
                start = nl + 1;
            }
            r.partial.erase(0, start);
            continue;
        }
        if (n < 0 && errno == EINTR) continue;
        if (n == 0) return false;
        return true;  // EAGAIN: nothing more for now
    }
}

}  // namespace

std::vector<ChildResult> runChildren(const std::vector<ChildTask>& tasks, int parallel,
                                     const std::function<void(size_t, const std::string&)>& onLine,
                                     const std::function<void(size_t, const ChildResult&)>& onDone) {
    std::vector<ChildResult> results(tasks.size());
    std::vector<Running> running;
    size_t next = 0;
    parallel = std::max(1, parallel);
    auto finish = [&](Running& r, int status) {
        if (r.fd >= 0) {
            // The child is gone: take the rest of its output (a grandchild
            // holding the pipe open must not block us, hence non-blocking).
            drain(r, onLine);
            if (!r.partial.empty() && onLine) onLine(r.task, r.partial);
            ::close(r.fd);
        }
        results[r.task] = resultOf(status);
        if (onDone) onDone(r.task, results[r.task]);
    };
    while (next < tasks.size() || !running.empty()) {
        while (next < tasks.size() && int(running.size()) < parallel) {
            const ChildTask& task = tasks[next];
            Running r;
            r.task = next++;
            int outFd = -1;
            std::string error;
            if (task.argv.empty()) {
                error = "empty command";
            } else if (!task.log.empty()) {
                std::error_code ec;
                if (task.log.has_parent_path()) fs::create_directories(task.log.parent_path(), ec);
                outFd = ::open(task.log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
                if (outFd < 0) error = cat("cannot write log ", task.log.string(), ": ", std::strerror(errno));
            } else {
                int fds[2];
                if (::pipe2(fds, O_CLOEXEC) != 0) {
                    error = cat("cannot create a pipe: ", std::strerror(errno));
                } else {
                    r.fd = fds[0];
                    outFd = fds[1];
                    ::fcntl(r.fd, F_SETFL, ::fcntl(r.fd, F_GETFL) | O_NONBLOCK);
                }
            }
            if (error.empty()) r.pid = spawn(task, outFd, error);
            if (outFd >= 0) ::close(outFd);
            if (r.pid < 0) {
                if (r.fd >= 0) ::close(r.fd);
                results[r.task].error = error;
                if (onDone) onDone(r.task, results[r.task]);
                continue;
            }
            running.push_back(std::move(r));
        }
        // Wait for output or for a child to end (polled every 50 ms: a child
        // writing to a log file gives no event).
        std::vector<pollfd> fds;
        for (const Running& r : running)
            if (r.fd >= 0) fds.push_back({r.fd, POLLIN, 0});
        if (!fds.empty()) {
            if (::poll(fds.data(), fds.size(), 50) > 0)
                for (Running& r : running)
                    if (r.fd >= 0) drain(r, onLine);
        } else if (!running.empty()) {
            ::usleep(50 * 1000);
        }
        for (size_t i = 0; i < running.size();) {
            int status = 0;
            const pid_t done = ::waitpid(running[i].pid, &status, WNOHANG);
            if (done == running[i].pid) {
                finish(running[i], status);
                running.erase(running.begin() + long(i));
            } else {
                ++i;
            }
        }
    }
    return results;
}

ChildResult runCapture(const std::vector<std::string>& argv, std::string& output) {
    output.clear();
    ChildTask task;
    task.label = argv.empty() ? "" : argv[0];
    task.argv = argv;
    if (!argv.empty() && argv[0].find('/') == std::string::npos) {
        const fs::path found = findProgram(argv[0]);
        if (found.empty()) {
            ChildResult r;
            r.error = cat(argv[0], " not found on PATH");
            return r;
        }
        task.argv[0] = found.string();
    }
    const std::vector<ChildResult> r =
        runChildren({task}, 1, [&](size_t, const std::string& line) { output += line + "\n"; }, nullptr);
    return r.front();
}

fs::path currentExecutable() {
    std::error_code ec;
    const fs::path self = fs::read_symlink("/proc/self/exe", ec);
    if (ec) throw Error("cannot find the running executable (/proc/self/exe): " + ec.message());
    return self;
}

fs::path findProgram(const std::string& program) {
    const char* path = std::getenv("PATH");
    std::string dirs = path ? path : "/usr/local/bin:/usr/bin:/bin";
    size_t start = 0;
    while (start <= dirs.size()) {
        const size_t end = std::min(dirs.find(':', start), dirs.size());
        const fs::path candidate = fs::path(dirs.substr(start, end - start)) / program;
        if (end > start && ::access(candidate.c_str(), X_OK) == 0) return candidate;
        start = end + 1;
    }
    return {};
}

std::string shellQuote(const std::string& word) {
    if (!word.empty() && word.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_./=:,+%@") ==
                             std::string::npos)
        return word;
    std::string q = "'";
    for (char c : word) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

}  // namespace hp
