#pragma once
/// @file
/// @brief What a file looks like from its first bytes, so a loader handed the wrong kind of file
/// says "not a cloth JSON (looks like an OpenVDB grid file)" instead of a parser's raw message.

#include <filesystem>
#include <string>
#include <string_view>

namespace weft {

/// @brief A phrase naming the kind of data `head` (a file's first bytes, up to ~512) starts with:
/// "an OpenVDB grid file", "a JSON text", "a BCC curve file", "a PNG image", "an OpenEXR image",
/// "a Wavefront OBJ text", "a CSV text", "a text file", "a binary file", "an empty file", ….
[[nodiscard]] std::string file_kind(std::string_view head);

/// @brief The file_kind of the first bytes of `path`; "an unreadable file" if it cannot be read.
[[nodiscard]] std::string file_kind_at(const std::filesystem::path& path);

/// @brief True when `head` is text (no NUL, few control characters): what a CSV or OBJ reader
/// can parse line by line. Binary formats with a signature (OpenVDB, PNG, …) are not text.
[[nodiscard]] bool looks_like_text(std::string_view head);

/// @brief `text` without a leading UTF-8 byte order mark (EF BB BF), which editors on Windows put
/// before JSON (RFC 8259 §8.1 lets a parser ignore it; nlohmann's parser refuses it in a string).
/// Every JSON input is read through it: the scene and cloth-spec parsers, and looks_like_json.
[[nodiscard]] std::string_view skip_utf8_bom(std::string_view text);

/// @brief True when `head` starts, after a UTF-8 byte order mark and white space, like a JSON
/// object or array.
[[nodiscard]] bool looks_like_json(std::string_view head);

}  // namespace weft
