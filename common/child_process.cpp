// run_program(): posix_spawnp() with the redirections as file actions, then waitpid().
//
// posix_spawnp is fork + exec done by the C library: on Linux it reports a program that
// cannot be executed through its return value, so a missing program is an error here, in the
// parent, instead of a child that prints something and exits 127.
#include "common/child_process.h"

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <iostream>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

extern char **environ;

namespace magbrush {

namespace {

// The spawn attributes' file actions, freed however we leave.
class FileActions
{
public:
  FileActions() { posix_spawn_file_actions_init(&actions_); }
  ~FileActions() { posix_spawn_file_actions_destroy(&actions_); }
  FileActions(const FileActions &) = delete;
  FileActions &operator=(const FileActions &) = delete;

  void open_as(int fd, const std::string &path)
  {
    posix_spawn_file_actions_addopen(&actions_, fd, path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  }
  void duplicate(int from, int to) { posix_spawn_file_actions_adddup2(&actions_, from, to); }
  const posix_spawn_file_actions_t *get() const { return &actions_; }

private:
  posix_spawn_file_actions_t actions_;
};

// The output files are opened by the child; check here first that they can be, so that the
// error names the file rather than saying the program could not start.
void check_writable(const std::string &path)
{
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  if (fd < 0)
    throw ChildProcessError("cannot write the output file '" + path + "': " + std::strerror(errno));
  ::close(fd);
}

std::string describe_signal(int signal_number)
{
  const char *name = strsignal(signal_number);
  return "signal " + std::to_string(signal_number) + (name ? std::string(" (") + name + ")" : "");
}

} // namespace

int run_program(const std::vector<std::string> &command, const ChildOutput &output)
{
  if (command.empty() || command[0].empty())
    throw ChildProcessError("run_program: no program given");

  FileActions actions;
  if (!output.stdout_path.empty())
  {
    check_writable(output.stdout_path);
    actions.open_as(STDOUT_FILENO, output.stdout_path);
  }
  if (output.stderr_to_stdout)
    actions.duplicate(STDOUT_FILENO, STDERR_FILENO);
  else if (!output.stderr_path.empty())
  {
    check_writable(output.stderr_path);
    actions.open_as(STDERR_FILENO, output.stderr_path);
  }

  std::vector<char *> argv;
  for (const auto &word : command)
    argv.push_back(const_cast<char *>(word.c_str()));
  argv.push_back(nullptr);

  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  pid_t pid = 0;
  const int spawn_error = posix_spawnp(&pid, argv[0], actions.get(), nullptr, argv.data(), environ);
  if (spawn_error != 0)
    throw ChildProcessError("cannot run '" + command[0] + "': " + std::strerror(spawn_error));

  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR)
      throw ChildProcessError("waiting for '" + command[0] + "': " + std::strerror(errno));
  if (WIFEXITED(status))
    return WEXITSTATUS(status);
  if (WIFSIGNALED(status))
    throw ChildProcessError("'" + command[0] + "' was killed by " + describe_signal(WTERMSIG(status)));
  throw ChildProcessError("'" + command[0] + "' stopped without an exit status");
}

std::string run_program_failure(const std::vector<std::string> &command, const ChildOutput &output)
{
  try
  {
    const int status = run_program(command, output);
    return status == 0 ? "" : "exit " + std::to_string(status);
  }
  catch (const ChildProcessError &e)
  {
    return e.what();
  }
}

bool program_exists(const std::string &name)
{
  if (name.empty())
    return false;
  if (name.find('/') != std::string::npos)
    return ::access(name.c_str(), X_OK) == 0;
  const char *path = std::getenv("PATH");
  std::string folders = path ? path : "/usr/local/bin:/usr/bin:/bin";
  std::size_t start = 0;
  while (start <= folders.size())
  {
    const std::size_t end = std::min(folders.find(':', start), folders.size());
    const std::string folder = end > start ? folders.substr(start, end - start) : ".";
    struct stat info;
    const std::string candidate = folder + "/" + name;
    if (::stat(candidate.c_str(), &info) == 0 && S_ISREG(info.st_mode) && ::access(candidate.c_str(), X_OK) == 0)
      return true;
    start = end + 1;
  }
  return false;
}

} // namespace magbrush
