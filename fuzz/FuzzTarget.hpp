#pragma once
// What every fuzz target shares (docs/hardening.md): the input written as the files a reader
// opens, and the rule that tells a clear error from a finding.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <stdexcept>
#include <string>
#include <string_view>
#include <typeinfo>
#include <vector>

namespace grainlink::fuzz {

/// An empty folder of this process for the files of one input (the previous input's are gone).
std::string freshFolder();

/// Writes `bytes` to `folder/name` (creating the folders in `name`) and returns the path.
std::string writeFile(const std::string &folder, const std::string &name, std::string_view bytes);

/// The whole input as the file `name` in a fresh folder; returns its path.
std::string inputFile(const std::uint8_t *data, std::size_t size, const std::string &name);

/// The input cut at each line "%%%%" into `n` parts (missing ones empty, extra ones joined to the
/// last), so that one input carries the files a reader needs together, e.g. experiments.yaml
/// and its data file; the seeds in fuzz/corpus/ are written that way.
std::vector<std::string_view> splitParts(const std::uint8_t *data, std::size_t size,
                                         std::size_t n);

/// With GRAINLINK_FUZZ_SHOW set, prints a refusal's message: to see that seeds are read (a
/// seed that is refused only explores the refusal).
void showRefusal(const char *message);

/// Prints what was found and aborts, so that libFuzzer keeps the input as a crash.
[[noreturn]] void finding(const std::string &what);

/// Runs `read` on the input. Returning, or throwing an exception whose message names
/// `must_name` (the file, or the folder of the input's files), is a clear outcome; an error
/// that does not say where (a bare std::bad_alloc or std::out_of_range, a library's own parse
/// error) is a finding, as is anything not a std::exception.
template <class Read> void expectClearError(const std::string &must_name, Read &&read) {
    try {
        read();
    } catch (const std::exception &e) {
        showRefusal(e.what());
        if (std::string_view(e.what()).find(must_name) == std::string_view::npos)
            finding(std::string("an error (") + typeid(e).name() + ") that does not name '" +
                    must_name + "': " + e.what());
    }
}

} // namespace grainlink::fuzz
