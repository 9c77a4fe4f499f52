#pragma once
// The web viewer's page template (web/, bundled by esbuild), embedded into the CLI at build time
// by cmake/EmbedViewer.cmake. Empty when the CLI was built without the bundle (no npm).

#include <string_view>

namespace primseg::cli {

/// The whole HTML page with every script and style inline; the data goes where
/// kViewerDataMarker stands. Empty if this build has no viewer.
std::string_view viewer_template();

inline constexpr std::string_view kViewerDataMarker = "<!--PRIMSEG_DATA-->";

}  // namespace primseg::cli
