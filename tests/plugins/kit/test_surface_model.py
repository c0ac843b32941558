"""The atlas choices a physics cannot use are refused with the fix named (CLI, one line)."""


def test_an_approximant_that_cannot_be_a_chart_basis_is_refused(run_cli, tmp_path):
    r = run_cli("pointatlas", "experiment=shell_plate", "approximant=shepard",
                "source.n_points=100", f"hydra.run.dir={tmp_path}/a", cwd=tmp_path)
    assert r.returncode != 0
    assert "approximant=shepard cannot be the basis of the atlas charts" in r.stderr + r.stdout
    assert "Traceback" not in r.stderr


def test_an_approximant_gamma_the_charts_do_not_use_is_refused(run_cli, tmp_path):
    r = run_cli("pointatlas", "experiment=shell_plate", "approximant=lme",
                "approximant.gamma=2.5", "source.n_points=100", f"hydra.run.dir={tmp_path}/b",
                cwd=tmp_path)
    assert r.returncode != 0
    assert "Write atlas.gamma_lme=2.5 instead" in r.stderr + r.stdout
