// foundation/file_write_queue.h: files handed over from many threads are all
// written whole; a failed file is reported by wait() (once) and does not stop
// the others.
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "foundation/file_write_queue.h"
#include "tests/common/temp_dir.h"

namespace vista {
namespace {

std::string contentOf(int i) {
    std::string s(size_t(1000 + 37 * i), '\0');
    for (size_t k = 0; k < s.size(); ++k) s[k] = char((k * 7 + size_t(i)) & 0xFF);
    return s;
}

TEST(FileWriteQueue, FilesGivenFromManyThreadsAreAllWrittenWholeByTheWait) {
    test::TempDir dir("vista_write_queue");
    FileWriteQueue io(3);
    std::vector<std::thread> givers;
    for (int t = 0; t < 4; ++t)
        givers.emplace_back([&, t] {
            for (int i = t; i < 40; i += 4) io.write(dir.file("f" + std::to_string(i)), contentOf(i));
        });
    for (std::thread& g : givers) g.join();
    ASSERT_TRUE(io.wait().isOk());
    std::set<std::string> want;
    for (int i = 0; i < 40; ++i) {
        EXPECT_EQ(test::readBytes(dir.file("f" + std::to_string(i))), contentOf(i)) << i;
        want.insert("f" + std::to_string(i));
    }
    EXPECT_EQ(test::listTree(dir.path()), want);  // no temporary left
}

TEST(FileWriteQueue, AFailedFileIsReportedOnceAndTheOthersAreStillWritten) {
    test::TempDir dir("vista_write_queue");
    const std::string bad = dir.file("missing/sub/x.bin");
    {
        FileWriteQueue io(1);
        io.write(dir.file("a"), "first");
        io.write(bad, "lost");
        io.write(dir.file("b"), "second");
        const Status s = io.wait();
        ASSERT_FALSE(s.isOk());
        EXPECT_NE(s.message().find(bad), std::string::npos) << s.message();
        EXPECT_TRUE(io.wait().isOk());     // reported once
        io.write(dir.file("c"), "third");  // given without a wait: the destructor writes it
    }
    EXPECT_EQ(test::readBytes(dir.file("a")), "first");
    EXPECT_EQ(test::readBytes(dir.file("b")), "second");
    EXPECT_EQ(test::readBytes(dir.file("c")), "third");
    EXPECT_EQ(test::listTree(dir.path()), (std::set<std::string>{"a", "b", "c"}));
}

}  // namespace
}  // namespace vista
