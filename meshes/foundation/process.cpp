#include "meshes/foundation/process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

extern char** environ;

namespace vessel {

namespace {

std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

std::string log_tail(const std::filesystem::path& p, int lines) {
  const std::string text = read_text(p);
  std::size_t end = text.size();
  while (end > 0 && (text[end - 1] == '\n' || text[end - 1] == '\r')) --end;
  std::size_t start = end;
  for (int n = 0; n < lines && start > 0; ++n) {
    start = text.rfind('\n', start - 1);
    if (start == std::string::npos) {
      start = 0;
      break;
    }
  }
  std::string t = text.substr(start, end - start);
  while (!t.empty() && t.front() == '\n') t.erase(t.begin());
  for (char& c : t) {
    if (c == '\n') c = '|';
  }
  return t;
}

ProcessResult run_process(const std::vector<std::string>& argv,
                          const std::filesystem::path& working_dir,
                          const std::vector<std::pair<std::string, std::string>>& env,
                          double timeout_s, const std::filesystem::path& log) {
  if (argv.empty()) throw std::invalid_argument("run_process: empty command");
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  // The environment: ours with `env` added (replacing a variable of the same name).
  std::vector<std::string> vars;
  for (char** e = environ; *e; ++e) {
    const std::string v = *e;
    const std::string name = v.substr(0, v.find('='));
    if (std::none_of(env.begin(), env.end(), [&](const auto& kv) { return kv.first == name; })) {
      vars.push_back(v);
    }
  }
  for (const auto& [k, v] : env) vars.push_back(k + "=" + v);
  std::vector<char*> envp;
  for (auto& v : vars) envp.push_back(v.data());
  envp.push_back(nullptr);
  const std::string dir = working_dir.empty() ? "." : working_dir.string();

  // posix_spawn (glibc: clone with CLONE_VFORK, no copy of this process's memory, so the child's
  // peak resident memory is its own), in its own process group so that a time-out kills what it
  // started too; stdin from /dev/null, stdout and stderr appended to the log.
  posix_spawn_file_actions_t actions;
  posix_spawnattr_t attributes;
  posix_spawn_file_actions_init(&actions);
  posix_spawnattr_init(&attributes);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attributes, 0);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                   O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addchdir_np(&actions, dir.c_str());
  const auto start = std::chrono::steady_clock::now();
  const auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  pid_t pid = 0;
  const int spawned =
      posix_spawnp(&pid, args[0], &actions, &attributes, args.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  if (spawned != 0) {
    std::ofstream(log, std::ios::app) << "vesselverify: cannot execute '" << argv.front()
                                      << "' in " << dir << ": " << std::strerror(spawned) << "\n";
    ProcessResult r;
    r.exit_code = 127;  // the shell's "command not found"
    return r;
  }
  ProcessResult r;
  int status = 0;
  struct rusage usage {};
  auto sleep_for = std::chrono::microseconds(200);
  while (true) {
    // Ended? Looked at without reaping it: while the leader is an unreaped zombie its group id
    // cannot be reused, so the group can be killed safely below.
    siginfo_t info{};
    const int w = waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOHANG | WNOWAIT);
    if (w < 0 && errno != EINTR) throw std::runtime_error(std::string("waitid: ") + std::strerror(errno));
    if (w == 0 && info.si_pid == pid) break;
    if (elapsed() > timeout_s) {
      r.timed_out = true;
      break;
    }
    std::this_thread::sleep_for(sleep_for);
    sleep_for = std::min(sleep_for * 2, std::chrono::microseconds(2000));
  }
  // The whole group: on a time-out the command and what it started; after a normal exit any
  // descendant it left running.
  kill(-pid, SIGKILL);
  while (wait4(pid, &status, 0, &usage) < 0 && errno == EINTR) {
  }
  r.wall_seconds = elapsed();
  if (WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) r.signal = WTERMSIG(status);
  return r;
}

}  // namespace vessel
