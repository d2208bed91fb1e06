"""The campaign's user errors: each str(err) is one sentence the command line prints as it is."""

from __future__ import annotations

from typing import Any


class CampaignError(Exception):
    """A campaign that cannot start: a missing scenario, a bad case file, an output of other cases."""


class CaseError(CampaignError, ValueError):
    """A case definition written wrongly (a key, a distribution, a parameter, a fault)."""


class CampaignInterrupted(KeyboardInterrupt):
    """Ctrl-C during a campaign: the summary of the cases finished so far (`summary`), how many of this run's
    `to_fly` cases finished (`flown`). The results file keeps every finished row: the same command resumes."""

    def __init__(self, summary: Any, flown: int, to_fly: int) -> None:
        super().__init__(f"interrupted after {flown} of {to_fly} cases")
        self.summary, self.flown, self.to_fly = summary, flown, to_fly
