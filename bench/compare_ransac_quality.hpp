#pragma once
// primseg_compare_cgal --quality: primseg against CGAL's Efficient RANSAC on the generated shapes
// with ground truth (compare_ransac_quality.cpp). Prints a Markdown table; returns the exit code.
int run_ransac_quality_comparison(int seeds);
