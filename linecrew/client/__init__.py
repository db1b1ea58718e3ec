"""The operator CLI: ``linecrew submit|gesture|actions|cancel|status|plan|events|fault``."""
