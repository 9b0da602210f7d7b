#include "FuzzTarget.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace grainlink::fuzz {

namespace fs = std::filesystem;

std::string freshFolder() {
    static const fs::path folder =
        fs::temp_directory_path() / ("grainlink-fuzz-" + std::to_string(::getpid()));
    static const bool cleaned_at_exit = [] {
        std::atexit([] {
            std::error_code ignored;
            fs::remove_all(folder, ignored);
        });
        return true;
    }();
    (void)cleaned_at_exit;
    fs::remove_all(folder);
    fs::create_directories(folder);
    return folder.string();
}

std::string writeFile(const std::string &folder, const std::string &name, std::string_view bytes) {
    const fs::path path = fs::path(folder) / name;
    fs::create_directories(path.parent_path());
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return path.string();
}

std::string inputFile(const std::uint8_t *data, std::size_t size, const std::string &name) {
    return writeFile(freshFolder(), name,
                     std::string_view(reinterpret_cast<const char *>(data), size));
}

std::vector<std::string_view> splitParts(const std::uint8_t *data, std::size_t size,
                                         std::size_t n) {
    constexpr std::string_view cut = "\n%%%%\n";
    std::string_view rest(reinterpret_cast<const char *>(data), size);
    std::vector<std::string_view> parts;
    while (parts.size() + 1 < n) {
        const std::size_t at = rest.find(cut);
        if (at == std::string_view::npos)
            break;
        parts.push_back(rest.substr(0, at + 1)); // keeps the part's last newline
        rest.remove_prefix(at + cut.size());
    }
    parts.push_back(rest);
    parts.resize(n);
    return parts;
}

void showRefusal(const char *message) {
    static const bool show = std::getenv("GRAINLINK_FUZZ_SHOW") != nullptr;
    if (show)
        std::fprintf(stderr, "refused: %s\n", message);
}

void finding(const std::string &what) {
    std::fprintf(stderr, "fuzz finding: %s\n", what.c_str());
    std::fflush(stderr);
    std::abort();
}

} // namespace grainlink::fuzz
