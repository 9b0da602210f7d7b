#pragma once
// What the coupling library logs while one of these lives (spdlog's default logger), so a test
// can check that a hostile peer cannot forge or flood log lines.
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <memory>
#include <sstream>
#include <string>

namespace grainlink::testing {

class LogCapture {
public:
    LogCapture()
        : previous_(spdlog::default_logger()),
          sink_(std::make_shared<spdlog::sinks::ostream_sink_mt>(text_)) {
        sink_->set_pattern("%v");
        spdlog::set_default_logger(std::make_shared<spdlog::logger>("capture", sink_));
    }
    ~LogCapture() { spdlog::set_default_logger(previous_); }
    LogCapture(const LogCapture &) = delete;
    LogCapture &operator=(const LogCapture &) = delete;

    std::string text() {
        spdlog::default_logger()->flush();
        return text_.str();
    }

private:
    std::shared_ptr<spdlog::logger> previous_;
    std::ostringstream text_;
    std::shared_ptr<spdlog::sinks::ostream_sink_mt> sink_;
};

} // namespace grainlink::testing
