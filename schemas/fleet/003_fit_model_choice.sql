-- Central (fleet) schema, version 3: station migration 9's record of how a fit's model was
-- chosen (`station fit --select`, or a part file that fixes it). NULL: given by hand, or older.
ALTER TABLE fits ADD COLUMN model_choice_json text;
