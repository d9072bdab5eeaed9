"""Pages in the Meshcat control panel for a person at the browser."""
