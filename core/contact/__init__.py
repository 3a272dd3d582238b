"""core.contact.unilateral."""
