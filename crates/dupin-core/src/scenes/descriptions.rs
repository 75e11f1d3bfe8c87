//! One sentence per scene for people: what it shows and where the paper shows it (the page
//! prints it under the scene picker).

/// The scenes' descriptions, in the order of [`super::PHEX_SCENES`] then [`super::PQ_SCENES`].
const DESCRIPTIONS: &[(&str, &str)] = &[
    (
        "cyclide-architecture",
        "A Dupin cyclide roof of planar hexagons whose shapes pass smoothly across the parabolic curve (P-Hex paper, Fig. 1).",
    ),
    (
        "sphere-radial",
        "A sphere panelled along a radial conjugate network: one of three patterns on the same surface (P-Hex paper, Fig. 20).",
    ),
    (
        "sphere-diverging",
        "A sphere panelled along a diverging conjugate network: the faces change size yet stay nearly affine regular (P-Hex paper, Fig. 20).",
    ),
    (
        "sphere-spiral",
        "A sphere panelled along a spiral conjugate network: the third pattern on the same surface (P-Hex paper, Fig. 20).",
    ),
    (
        "hyperboloid-invalid",
        "A hyperboloid triangulated against condition (3) of Proposition 5: its hexagons self-intersect, the paper's failure case (P-Hex paper, Fig. 11 top).",
    ),
    (
        "hyperboloid-valid",
        "The same hyperboloid with ideal triangles: every hexagon is valid, and non-convex where K < 0 (P-Hex paper, Fig. 11 bottom).",
    ),
    (
        "cyclide-progressive",
        "A cyclide by method 1, progressive conjugation: layer after layer from a base curve, nearly affine regular hexagons (P-Hex paper, Fig. 15 left).",
    ),
    (
        "cyclide-prescribed",
        "A cyclide by method 2, along prescribed conjugate curvature lines (P-Hex paper, Fig. 15 right).",
    ),
    (
        "vase-bottom-up",
        "A vase laid from the bottom up, with the step size carried across the parabolic curve (P-Hex paper, Fig. 18 left).",
    ),
    (
        "vase-longitudinal",
        "The vase laid along its length instead (P-Hex paper, Fig. 18 right).",
    ),
    (
        "torus-no-bound",
        "A torus without a lower bound on the step size: the layers turn narrow near the parabolic circles (P-Hex paper, Fig. 19 left).",
    ),
    (
        "torus-bound",
        "The torus with the lower bound b on the step size (section 5.3): the layers keep their width (P-Hex paper, Fig. 19 right).",
    ),
    (
        "minimal-surface",
        "A minimal surface (K < 0 everywhere) by method 2: every hexagon planar and non-convex (P-Hex paper, Fig. 21 left).",
    ),
    (
        "convex-loop",
        "A convex P-Hex mesh whose triangulation is Loop subdivision of a control mesh (P-Hex paper, Fig. 21 right).",
    ),
    (
        "freeform-parabolic",
        "A freeform surface whose conjugate network includes its parabolic curve, so the hexagons change shape smoothly across it (P-Hex paper, Fig. 22).",
    ),
    (
        "cylinder-developable",
        "A developable cylinder (K = 0), where the Dupin indicatrix degenerates to parallel lines (P-Hex paper, section 3).",
    ),
    (
        "pq-catmull-clark",
        "Catmull-Clark subdivision with a PQ perturbation at every level: a hierarchy of planar-quad meshes (conical paper, Fig. 7).",
    ),
    (
        "conical-station",
        "A station roof as a conical mesh: planar quads with offsets at constant face distance and planar support beams (conical paper, Figs. 1 and 14).",
    ),
    (
        "developable-trefoil",
        "A developable Möbius band in the shape of a trefoil knot, a PQ strip (conical paper, Fig. 9).",
    ),
    (
        "developable-strips",
        "Developable surfaces as PQ strips from developable subdivision, each strip unrolling flat (conical paper, Figs. 8 and 16).",
    ),
    (
        "circular-principal",
        "A circular mesh: every quad has a circumcircle, a discrete network of principal curvature lines (conical paper, Fig. 17).",
    ),
];

/// The one-sentence description of scene `name` (with its paper and figure), if it is a scene.
pub fn scene_description(name: &str) -> Option<&'static str> {
    DESCRIPTIONS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|&(_, d)| d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_scene_has_one_sentence_naming_its_paper() {
        let scenes: Vec<&str> = super::super::PHEX_SCENES
            .iter()
            .chain(super::super::PQ_SCENES)
            .copied()
            .collect();
        assert_eq!(
            DESCRIPTIONS.iter().map(|(n, _)| *n).collect::<Vec<_>>(),
            scenes
        );
        for s in scenes {
            let d = scene_description(s).unwrap();
            assert!(d.ends_with(").") && d.contains(" paper, "), "{s}: {d}");
            let plain = d.replace("Figs. ", "Figs ").replace("Fig. ", "Fig ");
            assert_eq!(plain.matches(". ").count(), 0, "{s}: one sentence");
        }
        assert_eq!(scene_description("torus"), None);
    }
}
