//! Photos -> apex heights (the only module that uses OpenCV).
