//! Frame sources (image folders, TIFF stacks, video via ffmpeg) and table readers/writers.
