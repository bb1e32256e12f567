-- Version 4.
-- * fits.std_errors_json now holds the honest standard errors: the spread of the OLS
--   coefficients under the error model fitted to the bins (white noise plus a Gauss-Markov
--   process, REML; compensation/correlated_errors.hpp). The textbook OLS figures, which assume
--   independent bins, move to std_errors_ols_json; error_model_json is that model
--   {"method","corr_time_s","correlated_share","sigma_dph","rho_per_bin"}.
-- * Fits stored before version 4 had only the OLS figures: they are copied into
--   std_errors_ols_json, and their error model says so ("method": "iid (stored before v4)").
--   Their std_errors_json keeps the OLS figures: the bins are still in the database, and
--   `station fit` gives the honest ones.
ALTER TABLE fits ADD COLUMN std_errors_ols_json TEXT;
ALTER TABLE fits ADD COLUMN error_model_json TEXT;
UPDATE fits SET std_errors_ols_json = std_errors_json,
                error_model_json = '{"method":"iid (stored before v4)"}';
