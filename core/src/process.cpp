#include <strata/core/process.hpp>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

extern char** environ;

namespace strata {
namespace {

// Closes a pipe end once (-1 when already closed).
void closeFd(int& fd) {
  if (fd >= 0) ::close(fd);
  fd = -1;
}

}  // namespace

Result<std::string> runProcess(const std::vector<std::string>& argv, std::string_view input) {
  STRATA_CHECK(!argv.empty() && !argv[0].empty() && argv[0][0] == '/') << "runProcess needs an absolute program path";
  int in[2] = {-1, -1}, out[2] = {-1, -1};
  if (::pipe2(in, O_CLOEXEC) != 0 || ::pipe2(out, O_CLOEXEC) != 0) {
    closeFd(in[0]);
    closeFd(in[1]);
    return fail(argv[0] + ": cannot create pipes: " + std::strerror(errno));
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, in[0], 0);
  posix_spawn_file_actions_adddup2(&actions, out[1], 1);
  posix_spawn_file_actions_adddup2(&actions, out[1], 2);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  // Its own process group: terminal signals (Ctrl-C to the foreground group) do not reach it. A
  // group signal sent before the child has left the group would still kill it (glibc resets
  // handled signals to their default in the child), so the terminal's signals are also blocked
  // in it: one sent in that window stays pending, harmlessly. (StrataCli.CtrlCWhilePlotsAreDrawn
  // KeepsTheReport lost the race under load: python died of the Ctrl-C before it started, and
  // strata died of SIGPIPE writing it the script.)
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGMASK);
  posix_spawnattr_setpgroup(&attr, 0);
  sigset_t terminal;
  sigemptyset(&terminal);
  for (int sig : {SIGINT, SIGQUIT, SIGTSTP}) sigaddset(&terminal, sig);
  posix_spawnattr_setsigmask(&attr, &terminal);
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int rc = ::posix_spawn(&pid, argv[0].c_str(), &actions, &attr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  closeFd(in[0]);
  closeFd(out[1]);
  if (rc != 0) {
    closeFd(in[1]);
    closeFd(out[0]);
    return fail(argv[0] + ": cannot start: " + std::strerror(rc));
  }
  // Feed stdin and drain stdout together, so neither side blocks on a full pipe.
  std::string output;
  size_t written = 0;
  if (input.empty()) closeFd(in[1]);
  char buf[4096];
  while (out[0] >= 0) {
    pollfd fds[2] = {{out[0], POLLIN, 0}, {in[1], POLLOUT, 0}};
    const int n = ::poll(fds, in[1] >= 0 ? 2 : 1, -1);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) break;
    if (in[1] >= 0 && (fds[1].revents & (POLLOUT | POLLERR | POLLHUP))) {
      const ssize_t w = ::write(in[1], input.data() + written, input.size() - written);
      if (w > 0) written += size_t(w);
      if (w < 0 && errno != EINTR && errno != EAGAIN) written = input.size();  // the child closed its stdin
      if (written >= input.size()) closeFd(in[1]);
    }
    if (fds[0].revents & (POLLIN | POLLHUP | POLLERR)) {
      const ssize_t r = ::read(out[0], buf, sizeof buf);
      if (r > 0) {
        output.append(buf, size_t(r));
      } else if (r == 0 || (errno != EINTR && errno != EAGAIN)) {
        closeFd(out[0]);
      }
    }
  }
  closeFd(in[1]);
  closeFd(out[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return output;
  const std::string how = WIFEXITED(status) ? "exited with status " + std::to_string(WEXITSTATUS(status))
                                            : "was killed by signal " + std::to_string(WTERMSIG(status));
  return fail(argv[0] + " " + how + (output.empty() ? "" : ": " + output));
}

bool machineIsBusy() {
  const long cores = sysconf(_SC_NPROCESSORS_ONLN);
  std::FILE* f = std::fopen("/proc/loadavg", "r");
  if (!f || cores < 1) {
    if (f) std::fclose(f);
    return false;
  }
  double load1 = 0, load5 = 0, load15 = 0;
  long running = 0, tasks = 0;
  const int n = std::fscanf(f, "%lf %lf %lf %ld/%ld", &load1, &load5, &load15, &running, &tasks);
  std::fclose(f);
  // `running` counts this process too. (Not the load averages: they remember the user's own run
  // that just ended.)
  return n == 5 && running - 1 >= cores;
}

void preferSleepingOpenMpWaits(char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") || !argv || !argv[0] || !machineIsBusy()) return;
  if (setenv("OMP_WAIT_POLICY", "PASSIVE", 0) != 0) return;
  execv("/proc/self/exe", argv);  // only returns on failure: go on as we are
}

}  // namespace strata
