# The web viewer of `primseg view`: web/ is bundled by esbuild into one HTML page that the CLI
# embeds. With web/node_modules installed (cd web && npm ci) the page is rebuilt from web/src
# whenever it changes; else a prebuilt web/dist/viewer.html is used if present; else the CLI is
# built without it and `primseg view` says how to enable it.
set(PRIMSEG_WEB_DIR ${PROJECT_SOURCE_DIR}/web)
find_program(PRIMSEG_NODE node)
set(viewer_page "")
if(PRIMSEG_NODE AND EXISTS ${PRIMSEG_WEB_DIR}/node_modules/esbuild)
  set(viewer_page ${PROJECT_BINARY_DIR}/viewer/viewer.html)
  file(GLOB_RECURSE viewer_sources CONFIGURE_DEPENDS ${PRIMSEG_WEB_DIR}/src/*)
  add_custom_command(OUTPUT ${viewer_page}
    COMMAND ${PRIMSEG_NODE} ${PRIMSEG_WEB_DIR}/build.mjs ${viewer_page}
    DEPENDS ${viewer_sources} ${PRIMSEG_WEB_DIR}/build.mjs ${PRIMSEG_WEB_DIR}/package-lock.json
    WORKING_DIRECTORY ${PRIMSEG_WEB_DIR}
    COMMENT "Bundling the web viewer (esbuild)")
  message(STATUS "primseg view: web viewer bundled from web/src")
elseif(EXISTS ${PRIMSEG_WEB_DIR}/dist/viewer.html)
  set(viewer_page ${PRIMSEG_WEB_DIR}/dist/viewer.html)
  message(STATUS "primseg view: prebuilt web/dist/viewer.html")
else()
  message(STATUS "primseg view: no web viewer (to enable it: cd web && npm ci, then reconfigure)")
endif()
set(viewer_source ${PROJECT_BINARY_DIR}/viewer/viewer_bundle.cpp)
add_custom_command(OUTPUT ${viewer_source}
  COMMAND ${CMAKE_COMMAND} -DINPUT=${viewer_page} -DOUTPUT=${viewer_source}
          -P ${PROJECT_SOURCE_DIR}/cmake/EmbedViewer.cmake
  DEPENDS ${viewer_page} ${PROJECT_SOURCE_DIR}/cmake/EmbedViewer.cmake
  COMMENT "Embedding the web viewer page")
target_sources(primseg_cli PRIVATE ${viewer_source})
# In a unity build the page stays its own translation unit: a new page recompiles only it, and the
# unity sources (which clang-tidy reads, scripts/tidy.sh) exist before anything is built.
set_source_files_properties(${viewer_source} PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)
target_include_directories(primseg_cli PRIVATE ${PROJECT_SOURCE_DIR}/apps)

# The browser tests (web/test/) in CTest, when the npm dependencies are installed.
function(primseg_add_viewer_tests)
  if(PRIMSEG_NODE AND EXISTS ${PRIMSEG_WEB_DIR}/node_modules/playwright-core)
    add_test(NAME web.viewer COMMAND ${PRIMSEG_NODE} --test ${PRIMSEG_WEB_DIR}/test/)
    set_tests_properties(web.viewer PROPERTIES RUN_SERIAL ON TIMEOUT 900
      ENVIRONMENT "PRIMSEG=$<TARGET_FILE:primseg_cli>;PRIMSEG_WEB_ARTIFACTS=${PROJECT_BINARY_DIR}/web-artifacts;PRIMSEG_STICK_FIGURE=$<TARGET_FILE:primseg_write_stick_figure>")
  endif()
endfunction()
