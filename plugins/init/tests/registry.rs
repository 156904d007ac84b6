//! The plugin registers its three solvers under their stable names.

use beltrami_core::Registry;

#[test]
fn registers_tutte_harmonic_and_lscm() {
    let mut registry = Registry::new();
    beltrami_init::register(&mut registry);
    assert_eq!(registry.names(), ["tutte", "harmonic", "lscm"]);
    for name in ["tutte", "harmonic", "lscm"] {
        let solver = registry.get(name).unwrap();
        assert_eq!(solver.name(), name);
        assert!(!solver.description().is_empty() && !solver.accepts().is_empty());
    }
}
