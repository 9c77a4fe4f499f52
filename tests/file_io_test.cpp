// Atomic writes under interruption: a program that calls defer_termination_during_writes() and is
// interrupted leaves each output whole or absent, never a temporary file. Each case runs in a
// child process, since the signals terminate it.
#include "file_io.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <set>
#include <string>

#include "support/test_support.hpp"

namespace primseg {
namespace {

namespace fs = std::filesystem;

std::set<std::string> names_in(const fs::path& directory) {
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(directory))
    names.insert(entry.path().filename().string());
  return names;
}

// Runs `body` in a child process, which exits with status 3 if body returns; the wait status.
int status_of_child(const std::function<void()>& body) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    body();
    std::_Exit(3);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return status;
}

bool terminated_by(int status, int signal_number) {
  return WIFSIGNALED(status) && WTERMSIG(status) == signal_number;
}

void raise_interrupt() {
  std::raise(SIGINT);
}

TEST(WriteFileAtomically, AnInterruptWhileTheFileIsNamedWaitsForTheRename) {
  const fs::path dir = testing::temp_directory("file-io-deferred");
  const fs::path target = dir / "out.txt";
  const int status = status_of_child([&] {
    detail::defer_termination_during_writes();
    detail::write_file_atomically(target, "complete contents", raise_interrupt);
  });
  EXPECT_TRUE(terminated_by(status, SIGINT)) << "wait status " << status;
  EXPECT_EQ(names_in(dir), std::set<std::string>{"out.txt"});
  EXPECT_EQ(testing::file_contents(target), "complete contents");
  fs::remove_all(dir);
}

TEST(WriteFileAtomically, WithoutTheHandlersTheSameInterruptLeavesTheTemporaryFile) {
  // What the handlers are for: the same interruption in a program without them.
  const fs::path dir = testing::temp_directory("file-io-default");
  const int status = status_of_child(
      [&] { detail::write_file_atomically(dir / "out.txt", "contents", raise_interrupt); });
  EXPECT_TRUE(terminated_by(status, SIGINT)) << "wait status " << status;
  const std::set<std::string> names = names_in(dir);
  ASSERT_EQ(names.size(), 1u);
  EXPECT_EQ(names.begin()->rfind(".out.txt.tmp", 0), 0u) << *names.begin();
  fs::remove_all(dir);
}

TEST(WriteFileAtomically, OutsideWritesAnInterruptTerminatesAtOnce) {
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
    const int status = status_of_child([&] {
      detail::defer_termination_during_writes();
      std::raise(signal_number);
    });
    EXPECT_TRUE(terminated_by(status, signal_number))
        << "signal " << signal_number << ", wait status " << status;
  }
}

TEST(WriteFileAtomically, AnIgnoredInterruptStaysIgnored) {
  // Under nohup, say: the handlers must not turn an ignored signal into a termination.
  const int status = status_of_child([] {
    std::signal(SIGHUP, SIG_IGN);
    detail::defer_termination_during_writes();
    std::raise(SIGHUP);
  });
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 3) << "wait status " << status;
}

}  // namespace
}  // namespace primseg
