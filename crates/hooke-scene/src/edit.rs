//! Setting one key of a scene by its path in the scene file, as parameter sweeps do:
//! `simulation.dt`, `body.0.springs.structural.ks`, or `body.springs.structural.ks` for every
//! body. The edited scene is read back through the same checks as a file, so a bad value is
//! refused with its key.

use crate::error::BuildError;
use crate::spec::SceneSpec;

impl SceneSpec {
    /// Sets the value at `path`, the dotted keys of the scene file (`[[body]]` and
    /// `[[collider]]` are arrays: a number picks one element, no number sets the key in
    /// every element). The key must exist in the scene file or be one the format knows, and
    /// the value must pass the checks a file's would.
    ///
    /// ```
    /// let mut spec = hooke_scene::builtin::builtin("hanging-cloth").unwrap();
    /// spec.set("body.springs.structural.ks", toml::Value::Float(250.0)).unwrap();
    /// spec.set("simulation.dt", toml::Value::Float(1e-4)).unwrap();
    /// assert_eq!(spec.bodies[0].springs.structural.unwrap().ks.get(), 250.0);
    /// let e = spec.set("simulation.dt", toml::Value::Float(-1.0)).unwrap_err();
    /// assert!(e.to_string().contains("simulation.dt"), "{e}");
    /// assert!(spec.set("body.springz.ks", toml::Value::Float(1.0)).is_err());
    /// ```
    pub fn set(&mut self, path: &str, value: toml::Value) -> Result<(), BuildError> {
        let invalid = |message: String| BuildError::Invalid {
            key: path.to_string(),
            message,
        };
        let mut tree = toml::Value::try_from(&*self)
            .map_err(|e| invalid(format!("the scene cannot be edited: {e}")))?;
        let keys: Vec<&str> = path.split('.').collect();
        if keys.iter().any(|k| k.is_empty()) {
            return Err(invalid("expected dotted keys such as simulation.dt".into()));
        }
        let mut changed = 0;
        assign(&mut tree, &keys, &value, &mut changed).map_err(invalid)?;
        if changed == 0 {
            return Err(invalid("the scene has no element there".into()));
        }
        let edited: SceneSpec = tree
            .try_into()
            .map_err(|e: toml::de::Error| invalid(e.message().to_string()))?;
        *self = edited;
        Ok(())
    }
}

/// Sets `keys` below `node` to `value`, counting the places set.
fn assign(
    node: &mut toml::Value,
    keys: &[&str],
    value: &toml::Value,
    changed: &mut usize,
) -> Result<(), String> {
    let Some((key, rest)) = keys.split_first() else {
        *node = value.clone();
        *changed += 1;
        return Ok(());
    };
    match node {
        toml::Value::Array(items) => match key.parse::<usize>() {
            Ok(i) => {
                let len = items.len();
                let item = items
                    .get_mut(i)
                    .ok_or_else(|| format!("index {i} is beyond the {len} elements there"))?;
                assign(item, rest, value, changed)
            }
            // No index: every element.
            Err(_) => items
                .iter_mut()
                .try_for_each(|item| assign(item, keys, value, changed)),
        },
        toml::Value::Table(table) => {
            if rest.is_empty() {
                // A new leaf is fine (an optional key the file left out); the read-back
                // refuses keys the format does not know.
                table.insert(key.to_string(), value.clone());
                *changed += 1;
                return Ok(());
            }
            let known = names(table);
            let child = table
                .get_mut(*key)
                .ok_or_else(|| format!("no key '{key}' there (it has: {known})"))?;
            assign(child, rest, value, changed)
        }
        _ => Err(format!("'{key}' is below a value, not a table")),
    }
}

fn names(table: &toml::map::Map<String, toml::Value>) -> String {
    table.keys().cloned().collect::<Vec<_>>().join(", ")
}
