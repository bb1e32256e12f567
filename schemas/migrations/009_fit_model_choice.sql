-- Version 9 (issue 32): how a fit's model was chosen.
-- * fits.model_choice_json: written by `station fit --select` (compensation/model_selection.hpp):
--   {"method", "reason", "tried": [{"model", "step", "added", "held_out_rms_dph",
--   "likelihood_ratio", "not_fitted", "chosen"}]}, or {"method": "part file", "part_number",
--   "reason"} when the part file fixes the model. NULL: the terms were given (--terms or the
--   default), or the fit is older than version 9. A release refers to its fit, so it carries
--   which model and why.
ALTER TABLE fits ADD COLUMN model_choice_json TEXT;
