"""Robot models and the helpers that load them into Drake."""
