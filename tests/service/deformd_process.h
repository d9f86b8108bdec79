// The real deformd executable in a child process, for what only a process shows: signals
// (SIGHUP reloads tokens), restarts (--store), refusals at start-up. Its log goes to a file the
// test can read; the port is read from its "listening on HOST:PORT" line (start it with port 0).
#pragma once

#include <gtest/gtest.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace deform::test_support {

class DeformdProcess {
 public:
  // Starts `program` (default: the deformd built with the tests) with `args`, its output into
  // `log_file`.
  DeformdProcess(const std::vector<std::string>& args, std::string log_file,
                 const std::string& program = DEFORMD_PATH)
      : log_file_(std::move(log_file)) {
    pid_ = fork();
    if (pid_ == 0) {
      const int fd = ::open(log_file_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
      dup2(fd, 1);
      dup2(fd, 2);
      std::vector<char*> argv;
      argv.push_back(const_cast<char*>(program.c_str()));
      for (const std::string& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
      argv.push_back(nullptr);
      execv(program.c_str(), argv.data());
      _exit(127);
    }
  }
  ~DeformdProcess() {
    if (pid_ > 0 && !exited_) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  DeformdProcess(const DeformdProcess&) = delete;
  DeformdProcess& operator=(const DeformdProcess&) = delete;

  // Waits until the log says "listening on 127.0.0.1:PORT"; false if the process exits first or
  // `timeout` passes.
  bool WaitForListening(std::chrono::seconds timeout = std::chrono::seconds(120)) {
    const std::regex listening("listening on 127\\.0\\.0\\.1:([0-9]+)");
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      std::smatch match;
      const std::string log = Log();
      if (std::regex_search(log, match, listening)) {
        port_ = std::stoi(match[1]);
        return true;
      }
      if (Exited()) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }
  // Waits until the log contains `text`.
  bool WaitForLog(const std::string& text, std::chrono::seconds timeout = std::chrono::seconds(30)) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      if (Log().find(text) != std::string::npos) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }

  std::string target() const { return "127.0.0.1:" + std::to_string(port_); }
  void Signal(int signal_number) { kill(pid_, signal_number); }
  // Sends SIGTERM and returns the exit code (-1 if it did not exit normally).
  int Stop() {
    Signal(SIGTERM);
    return WaitForExit();
  }
  // Waits for the process to end; its exit code (-1 if it did not exit normally).
  int WaitForExit() {
    if (!exited_) {
      waitpid(pid_, &wait_status_, 0);
      exited_ = true;
    }
    return WIFEXITED(wait_status_) ? WEXITSTATUS(wait_status_) : -1;
  }
  std::string Log() const {
    std::ifstream in(log_file_);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
  }

 private:
  bool Exited() {
    if (exited_) return true;
    if (waitpid(pid_, &wait_status_, WNOHANG) == pid_) exited_ = true;
    return exited_;
  }

  std::string log_file_;
  pid_t pid_ = -1;
  int port_ = 0;
  bool exited_ = false;
  int wait_status_ = 0;
};

}  // namespace deform::test_support
