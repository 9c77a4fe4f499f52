// Atomic writes under interruption: a program that calls defer_termination_during_writes() and is
// interrupted leaves each output whole or absent, never a temporary file. Each case runs in a
// child process, since the signals terminate it. Targets that are not regular files (symbolic
// links, FIFOs, directories) are written through or refused, never replaced.
#include "file_io.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <set>
#include <string>

#include "primseg/error.hpp"
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

TEST(WriteFileAtomically, ASymbolicLinkIsFollowedAndKept) {
  const fs::path dir = testing::temp_directory("file-io-link");
  detail::write_file_atomically(dir / "real.txt", "old");
  fs::create_symlink("real.txt", dir / "link.txt");
  detail::write_file_atomically(dir / "link.txt", "new");
  EXPECT_TRUE(fs::is_symlink(dir / "link.txt"));
  EXPECT_EQ(testing::file_contents(dir / "real.txt"), "new");
  EXPECT_EQ(names_in(dir), (std::set<std::string>{"link.txt", "real.txt"}));
  fs::remove_all(dir);
}

// Before, the rename put a regular file in place of the target: `primseg skeleton ...
// --skin-weights /dev/full`, run as root, replaced the device /dev/full with the weights.
TEST(WriteFileAtomically, AFifoIsWrittenAsItIsNotReplaced) {
  const fs::path dir = testing::temp_directory("file-io-fifo");
  const fs::path fifo = dir / "out.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  // Its reader opens first, without waiting for a writer: a regression then fails, never hangs.
  const int reader = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(reader, 0);
  detail::write_file_atomically(fifo, "through the pipe");
  char received[64] = {};
  const ssize_t got = ::read(reader, received, sizeof received - 1);
  ::close(reader);
  EXPECT_EQ(std::string(received, got > 0 ? static_cast<std::size_t>(got) : 0), "through the pipe");
  struct stat status {};
  ASSERT_EQ(::lstat(fifo.c_str(), &status), 0);
  EXPECT_TRUE(S_ISFIFO(status.st_mode));
  EXPECT_EQ(names_in(dir), std::set<std::string>{"out.fifo"});
  fs::remove_all(dir);
}

TEST(WriteFileAtomically, ADirectoryIsAnErrorNamingIt) {
  const fs::path dir = testing::temp_directory("file-io-directory");
  fs::create_directory(dir / "out");
  try {
    detail::write_file_atomically(dir / "out", "bytes");
    ADD_FAILURE() << "no exception";
  } catch (const IoError& error) {
    EXPECT_EQ(std::string(error.what()),
              "cannot write '" + (dir / "out").string() + "': Is a directory");
  }
  EXPECT_TRUE(fs::is_directory(dir / "out"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace primseg
