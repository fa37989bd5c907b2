#pragma once
// Where the build tree and the source tree are, found when a test runs: the build directory is the nearest
// one above the test executable that holds CMakeCache.txt, the source directory the one that cache names. No
// absolute path is compiled into a test, so that a compiler cache serves a clone of the tree in another
// directory too (CI sets CCACHE_BASEDIR to the clone's top, which makes every other path relative).
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

namespace airseg::test {
namespace tree_paths_detail {

struct Dirs {
    std::string binary;
    std::string source;
};

inline Dirs find_dirs() {
    std::error_code ec;
    const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (ec) {
        throw std::runtime_error("cannot read /proc/self/exe: " + ec.message());
    }
    for (auto dir = exe.parent_path(); !dir.empty(); dir = dir.parent_path()) {
        std::ifstream cache(dir / "CMakeCache.txt");
        const std::string key = "CMAKE_HOME_DIRECTORY:INTERNAL=";
        for (std::string line; cache && std::getline(cache, line);) {
            if (line.compare(0, key.size(), key) == 0) {
                return {dir.string(), line.substr(key.size())};
            }
        }
        if (dir == dir.root_path()) {
            break;
        }
    }
    throw std::runtime_error("no CMakeCache.txt naming the source directory above " + exe.string());
}

inline const Dirs& dirs() {
    static const Dirs found = find_dirs();
    return found;
}

}  // namespace tree_paths_detail

/// The top of the build tree this test executable belongs to (where CMakeCache.txt is).
inline const std::string& binary_dir() {
    return tree_paths_detail::dirs().binary;
}
/// The top of the source tree it was built from.
inline const std::string& source_dir() {
    return tree_paths_detail::dirs().source;
}

}  // namespace airseg::test
