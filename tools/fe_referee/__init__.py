"""The finite-element referee of the block cases by CalculiX, split by subject;
tools/fe-referee.py is its command."""
