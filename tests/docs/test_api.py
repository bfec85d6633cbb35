"""The library API: ``model`` offers the entry points a script needs, each with a runnable example
in its docstring, and the examples run (as doctests); ``EigenResult.real`` is a deprecated alias."""

from __future__ import annotations

import doctest

import pytest

import model

ENTRY_POINTS = ("load_parameters", "build_model", "default_operating_point", "eigen_analysis",
                "stability_limit", "root_locus", "short_circuit_response", "nonlinear_response",
                "required_reaction_time", "eigen_sensitivities", "limit_sensitivity",
                "peak_load_sensitivities", "run_envelope", "frequency_response", "campbell")
CHEAP = ("load_parameters", "build_model", "default_operating_point", "eigen_analysis",
         "short_circuit_response")  # the others take seconds each: the slow layer


def test_every_entry_point_is_exported_with_an_example():
    finder = doctest.DocTestFinder(recurse=False)
    missing = [name for name in ENTRY_POINTS
               if name not in model.__all__ or not any(t.examples for t in finder.find(getattr(model, name)))]
    assert missing == []
    assert sorted(model.__all__) == sorted(set(model.__all__))
    assert all(hasattr(model, name) for name in model.__all__)


def _run_examples(name: str) -> None:
    finder = doctest.DocTestFinder(recurse=False)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    for test in finder.find(getattr(model, name), name, globs={}):
        runner.run(test)
    result = runner.summarize(verbose=False)
    assert result.attempted > 0
    assert result.failed == 0, f"{name}: {result.failed} of {result.attempted} examples failed"


@pytest.mark.parametrize("name", CHEAP)
def test_the_cheap_examples_run(name):
    _run_examples(name)


@pytest.mark.slow
@pytest.mark.parametrize("name", [n for n in ENTRY_POINTS if n not in CHEAP])
def test_the_longer_examples_run(name):
    _run_examples(name)


def test_real_is_a_deprecated_alias_of_real_eigenvalues():
    parameters = model.load_parameters()
    result = model.eigen_analysis(model.build_model(parameters),
                                  model.default_operating_point(parameters, s0=0.014),
                                  vectors=False)
    with pytest.warns(DeprecationWarning, match="real_eigenvalues"):
        old = result.real
    assert (old == result.real_eigenvalues).all()
    assert result.real_eigenvalues[0] > 0  # the real eigenvalues, largest first; not real parts
    assert len(result.real_eigenvalues) < len(result.eigenvalues)
