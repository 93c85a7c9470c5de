// The Markdown and number formatting every section of RESULTS.md shares (markdown.cpp): fixed
// decimals with "—" for missing values, tables, GitHub heading anchors, code blocks, "not run".
#pragma once

#include <string>
#include <vector>

namespace animorder::results {

extern const char* const kDash;  // a missing value: "—"

std::string f3(double v);        // 3 decimals, or — when not finite
std::string f1(double v);        // 1 decimal, or — when not finite
std::string count(long long v);  // the integer, or — when negative

// λ as written in the reports' settings: 0.85, 3, 1.5 (— when not finite).
std::string lambda_text(double v);
bool same_lambda(double a, double b);  // both finite and equal to 1e-9

// A Markdown table: the first `text_columns` columns left-aligned, the numbers right-aligned.
std::string table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows,
                  size_t text_columns = 1);

// GitHub's heading anchors: lower case, letters, digits, '-' and '_' kept, spaces to '-'.
std::string slug(const std::string& heading);

std::string not_run(const std::string& file);  // "not run: FILE missing\n"

// `text` verbatim in a ```text block (~~~~ fences when the text holds ```).
std::string code_block(const std::string& text);

// Text without trailing blank lines or spaces.
std::string trimmed(std::string text);

}  // namespace animorder::results
