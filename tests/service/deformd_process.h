// The real deformd executable as a child process, for tests of what only a process shows: binding
// its address, the health descriptor linked into the binary, signals and exit codes.
//
// Its standard output and error go to one temporary file that the test can search. The
// destructor kills the process if it still runs. Not thread-safe.
#pragma once

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace deform::test_support {

class DeformdProcess {
 public:
  // Starts DEFORMD_BINARY (or $DEFORM_TEST_DEFORMD, to probe another build) with `args`.
  explicit DeformdProcess(const std::vector<std::string>& args) {
    char path[] = "/tmp/deformd-test-XXXXXX";
    const int fd = mkstemp(path);
    EXPECT_GE(fd, 0);
    output_path_ = path;
    pid_ = fork();
    if (pid_ == 0) {
      dup2(fd, STDOUT_FILENO);
      dup2(fd, STDERR_FILENO);
      std::vector<char*> argv;
      const char* other = std::getenv("DEFORM_TEST_DEFORMD");
      std::string binary = other != nullptr ? other : DEFORMD_BINARY;
      argv.push_back(binary.data());
      std::vector<std::string> copies = args;
      for (std::string& arg : copies) argv.push_back(arg.data());
      argv.push_back(nullptr);
      execv(binary.c_str(), argv.data());
      _exit(127);
    }
    close(fd);
  }

  ~DeformdProcess() {
    if (running()) {
      kill(pid_, SIGKILL);
      Wait(std::chrono::seconds(10));
    }
    std::remove(output_path_.c_str());
  }

  // Everything the process has written so far.
  std::string output() const {
    std::ifstream in(output_path_);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  }

  // Waits until the output matches `pattern` (std::regex, searched); the first capture group of
  // the match, or nullopt on timeout or exit.
  std::optional<std::string> WaitForOutput(const std::string& pattern,
                                           std::chrono::milliseconds timeout) {
    const std::regex expression(pattern);
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      std::smatch match;
      const std::string text = output();
      if (std::regex_search(text, match, expression)) {
        return match.size() > 1 ? match[1].str() : match[0].str();
      }
      if (!running()) return std::nullopt;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return std::nullopt;
  }

  // The port of the "listening on HOST:PORT" line, or 0.
  int WaitForListeningPort(std::chrono::milliseconds timeout = std::chrono::seconds(60)) {
    const auto port = WaitForOutput("listening on [^ ]*:([0-9]+) ", timeout);
    return port.has_value() ? std::stoi(*port) : 0;
  }

  void Signal(int signal_number) { kill(pid_, signal_number); }

  // The exit code once the process has exited (-signal if a signal ended it), or nullopt on
  // timeout.
  std::optional<int> Wait(std::chrono::milliseconds timeout) {
    if (exit_code_.has_value()) return exit_code_;
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (true) {
      int status = 0;
      const pid_t done = waitpid(pid_, &status, WNOHANG);
      if (done == pid_) {
        exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
        return exit_code_;
      }
      if (std::chrono::steady_clock::now() >= deadline) return std::nullopt;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }

  bool running() { return !exit_code_.has_value() && !Wait(std::chrono::milliseconds(0)); }

 private:
  pid_t pid_ = -1;
  std::string output_path_;
  std::optional<int> exit_code_;
};

}  // namespace deform::test_support
