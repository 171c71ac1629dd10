//! Empty: the validation suite lives in the workspace's `tests/` folder.
