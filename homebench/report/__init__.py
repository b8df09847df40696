"""Tables, figures and the PDF report."""
