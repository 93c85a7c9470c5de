// The one check every loader test makes of a bad file: loading it throws a LoadError whose text is
// one line, starts with the file's path and says what is wrong.
#pragma once

#include "animorder/load.h"

#include <gtest/gtest.h>

#include <functional>
#include <string>

namespace animorder::test {

// `load` (which reads `file`) throws a one-line LoadError starting with `file` and holding `message`.
inline void expect_one_line_load_error(const std::string& file, const std::string& message,
                                       const std::function<void()>& load) {
    try {
        load();
        ADD_FAILURE() << file << ": no error";
    } catch (const LoadError& e) {
        const std::string what = e.what();
        EXPECT_EQ(what.rfind(file, 0), 0u) << what;
        EXPECT_NE(what.find(message), std::string::npos) << file << ": " << what;
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
}

}  // namespace animorder::test
