//! Pixel algorithms with no file IO: Gaussian, DoG/LoG, median, local maxima, sub-pixel fits, background models.
