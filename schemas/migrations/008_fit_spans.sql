-- Version 8 (issue 31): the span of temperature and gradient a fit saw, computed once.
-- * bins.temp_min_c, temp_max_c, grad_min_c, grad_max_c: the range of the bin's own 1 Hz
--   samples (compensation::make_bins), written when the run is binned.
-- * fits.temp_min_c, temp_max_c, grad_min_c, grad_max_c: the range over the complete bins the
--   fit used, written with the fit; a coefficient block clamps T and gradT to it.
-- NULL in both: binned or fitted before version 8. A block of such a fit finds its span from the
-- 1 Hz samples of its complete bins, as every version before did (release/coefficient_block.cpp),
-- so a calibration released earlier exports exactly as it did.
ALTER TABLE bins ADD COLUMN temp_min_c REAL;
ALTER TABLE bins ADD COLUMN temp_max_c REAL;
ALTER TABLE bins ADD COLUMN grad_min_c REAL;
ALTER TABLE bins ADD COLUMN grad_max_c REAL;
ALTER TABLE fits ADD COLUMN temp_min_c REAL;
ALTER TABLE fits ADD COLUMN temp_max_c REAL;
ALTER TABLE fits ADD COLUMN grad_min_c REAL;
ALTER TABLE fits ADD COLUMN grad_max_c REAL;
