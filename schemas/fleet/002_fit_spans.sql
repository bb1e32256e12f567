-- Central (fleet) schema, version 2: the spans of station migration 8. A bin's range of its 1 Hz
-- temperatures and gradients, and a fit's range over the complete bins it used (the span a
-- coefficient block clamps T and gradT to). NULL: binned or fitted before station migration 8.
ALTER TABLE bins ADD COLUMN temp_min_c double precision;
ALTER TABLE bins ADD COLUMN temp_max_c double precision;
ALTER TABLE bins ADD COLUMN grad_min_c double precision;
ALTER TABLE bins ADD COLUMN grad_max_c double precision;
ALTER TABLE fits ADD COLUMN temp_min_c double precision;
ALTER TABLE fits ADD COLUMN temp_max_c double precision;
ALTER TABLE fits ADD COLUMN grad_min_c double precision;
ALTER TABLE fits ADD COLUMN grad_max_c double precision;
