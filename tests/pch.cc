// The translation unit that compiles the test programs' precompiled headers
// (target mjslam_test_pch in the top CMakeLists.txt);
// every test program reuses them. It defines nothing.
