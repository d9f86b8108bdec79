// The real deformd executable as a child process, for tests of what only a process shows: binding
// its address, the health descriptor linked into the binary, signals (SIGHUP reloads tokens,
// SIGTERM drains), restarts (--store), refusals at start-up, exit codes.
//
// Its standard output and error go to one file the test can search (a temporary one unless named;
// a temporary one is removed with the object). The port is read from its "listening on
// HOST:PORT" line (start it with port 0). The destructor kills the process if it still runs. Not
// thread-safe.
#pragma once

#include <fcntl.h>
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
  // Starts `program` (default: $DEFORM_TEST_DEFORMD, to probe another build, or the deformd built
  // with the tests) with `args`, its output into `log_file` (default: a temporary file).
  explicit DeformdProcess(const std::vector<std::string>& args, std::string log_file = "",
                          std::string program = "") {
    int fd = -1;
    if (log_file.empty()) {
      char path[] = "/tmp/deformd-test-XXXXXX";
      fd = mkstemp(path);
      log_file_ = path;
      temporary_ = true;
    } else {
      log_file_ = std::move(log_file);
      fd = ::open(log_file_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    }
    EXPECT_GE(fd, 0);
    if (program.empty()) {
      const char* other = std::getenv("DEFORM_TEST_DEFORMD");
      program = other != nullptr ? other : DEFORMD_PATH;
    }
    pid_ = fork();
    if (pid_ == 0) {
      dup2(fd, STDOUT_FILENO);
      dup2(fd, STDERR_FILENO);
      std::vector<char*> argv;
      argv.push_back(program.data());
      std::vector<std::string> copies = args;
      for (std::string& arg : copies) argv.push_back(arg.data());
      argv.push_back(nullptr);
      execv(program.c_str(), argv.data());
      _exit(127);
    }
    close(fd);
  }

  ~DeformdProcess() {
    if (running()) {
      kill(pid_, SIGKILL);
      Wait(std::chrono::seconds(10));
    }
    if (temporary_) std::remove(log_file_.c_str());
  }
  DeformdProcess(const DeformdProcess&) = delete;
  DeformdProcess& operator=(const DeformdProcess&) = delete;

  // Everything the process has written so far.
  std::string output() const {
    std::ifstream in(log_file_);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  }
  std::string Log() const { return output(); }

  // Waits until the output matches `pattern` (std::regex, searched); the first capture group of
  // the match (or the match), or nullopt on timeout or exit.
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

  // Waits until the output contains `text`.
  bool WaitForLog(const std::string& text,
                  std::chrono::seconds timeout = std::chrono::seconds(30)) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      if (output().find(text) != std::string::npos) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }

  // The port of the "listening on HOST:PORT" line, or 0 on timeout or exit.
  int WaitForListeningPort(std::chrono::milliseconds timeout = std::chrono::seconds(60)) {
    const auto port = WaitForOutput("listening on [^ ]*:([0-9]+)", timeout);
    if (port.has_value()) port_ = std::stoi(*port);
    return port_;
  }
  // The same as a bool; target() is then "127.0.0.1:PORT".
  bool WaitForListening(std::chrono::seconds timeout = std::chrono::seconds(120)) {
    return WaitForListeningPort(timeout) != 0;
  }
  std::string target() const { return "127.0.0.1:" + std::to_string(port_); }

  void Signal(int signal_number) { kill(pid_, signal_number); }
  pid_t pid() const { return pid_; }

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
  // Waits for the process to end: its exit code (-1 if a signal ended it).
  int WaitForExit() {
    const std::optional<int> code = Wait(std::chrono::hours(1));
    return code.has_value() && *code >= 0 ? *code : -1;
  }
  // Sends SIGTERM and returns the exit code (-1 if it did not exit normally).
  int Stop() {
    Signal(SIGTERM);
    return WaitForExit();
  }

  bool running() { return !exit_code_.has_value() && !Wait(std::chrono::milliseconds(0)); }

 private:
  pid_t pid_ = -1;
  std::string log_file_;
  bool temporary_ = false;
  int port_ = 0;
  std::optional<int> exit_code_;
};

}  // namespace deform::test_support
