//! The plugin registers its solvers under their stable names.

use beltrami_core::Registry;

#[test]
fn registers_tutte_harmonic_lscm_and_sphere() {
    let mut registry = Registry::new();
    beltrami_init::register(&mut registry);
    assert_eq!(registry.names(), ["tutte", "harmonic", "lscm", "sphere"]);
    for name in ["tutte", "harmonic", "lscm", "sphere"] {
        let solver = registry.get(name).unwrap();
        assert_eq!(solver.name(), name);
        let accepts = solver.accepts();
        assert!(
            !solver.description().is_empty()
                && !accepts.elements.is_empty()
                && !accepts.topologies.is_empty()
                && !accepts.targets.is_empty()
                && !accepts.goals.is_empty()
        );
    }
    assert!(registry.get("nope").is_err());
}
