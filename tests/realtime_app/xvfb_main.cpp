// main() of the app tests: the view tests need an X display, so without one
// the program runs itself again under xvfb-run (listing tests needs none).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  bool listing = false;
  for (int i = 1; i < argc; ++i) listing |= std::strncmp(argv[i], "--gtest_list_tests", 18) == 0;
  if (!listing && !std::getenv("DISPLAY") && !std::getenv("PUNCTURE_TEST_UNDER_XVFB")) {
    setenv("PUNCTURE_TEST_UNDER_XVFB", "1", 1);
    const std::string server = std::to_string(100 + getpid() % 800);
    std::vector<char*> args{const_cast<char*>("xvfb-run"), const_cast<char*>("-a"), const_cast<char*>("-n"),
                            const_cast<char*>(server.c_str())};
    for (int i = 0; i < argc; ++i) args.push_back(argv[i]);
    args.push_back(nullptr);
    execvp("xvfb-run", args.data());
    std::perror("xvfb-run (install xvfb: scripts/setup.sh)");
    return 1;
  }
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
