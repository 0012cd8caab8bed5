#pragma once
// Runs a command line as a user would and keeps what it printed (stdout and stderr) and its exit
// status: how the tests drive tissueprobe-cli.
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace tp::test {

struct CommandRun {
  int status = -1;     // the exit status; -1 when it did not exit normally
  std::string output;  // stdout and stderr
};

inline CommandRun runCommand(const std::string& commandLine) {
  const std::string cmd = commandLine + " 2>&1";
  CommandRun r;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf{};
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) r.output.append(buf.data(), n);
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

}  // namespace tp::test
